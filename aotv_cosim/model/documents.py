"""Reading scenario and wiring files: strict JSON, then the shipped JSON schemas.

Files are data: nothing in them is evaluated. NaN and Infinity literals, which Python's json
module would accept, numbers too large for a float (1e400, which it would read as infinity) and
duplicate keys are refused.
"""

import json
import re
from importlib import resources
from pathlib import Path

import jsonschema

from aotv_cosim.errors import InputError, raise_if_any
from aotv_cosim.paths import MAX_DOCUMENT_BYTES, regular_file

SCHEMAS = {"wiring": "wiring.schema.json", "scenario": "scenario.schema.json",
           "compare": "compare.schema.json", "dispersions": "dispersions.schema.json"}

_FIXES = {
    "required": "add the missing field",
    "additionalProperties": "remove it or correct its spelling",
    "type": "give a value of the type the schema asks for",
    "enum": "use one of the allowed values",
    "pattern": "follow the documented form (component.variable, 'a.y -> b.u')",
    "exclusiveMinimum": "give a positive value",
    "minimum": "give a larger value",
    "minProperties": "add at least one entry",
    "minItems": "add at least one item",
    "anyOf": "give one of the alternatives (for an expectation: tolerance or rel_tolerance)",
    "oneOf": "give one of the alternatives",
}


def schema(kind: str) -> dict:
    """The JSON schema of a file kind ('wiring' or 'scenario'), as shipped in aotv_cosim/schemas."""
    text = resources.files("aotv_cosim").joinpath("schemas").joinpath(SCHEMAS[kind]).read_text()
    return json.loads(text)


class _Refused(ValueError):
    """A value the strict reader refuses; `token` is its text in the file, `key` a duplicated key."""

    def __init__(self, message, token=None, key=None):
        super().__init__(message)
        self.token, self.key = token, key


def _refuse_constant(name):
    raise _Refused(f"{name} is not a finite number", token=name)


def _finite_float(text):
    value = float(text)
    if value in (float("inf"), float("-inf")):
        raise _Refused(f"{text} is not a finite number", token=text)
    return value


def _float_sized_int(text):
    value = int(text)
    if abs(value) > 1.7976931348623157e308:
        raise _Refused(f"{text[:20]}{'...' if len(text) > 20 else ''} is too large for a float", token=text)
    return value


def _no_duplicates(pairs):
    """The object of `pairs`, refusing a repeated key (the first one repeated); linear time."""
    result = dict(pairs)
    if len(result) < len(pairs):
        seen = set()
        for key, _ in pairs:
            if key in seen:
                raise _Refused(f"duplicate key {key!r}", key=key)
            seen.add(key)
    return result


def strict_json(text: str):
    """json.loads refusing NaN, Infinity, numbers beyond the float range and duplicate keys
    (ValueError). A leading byte order mark (an editor's UTF-8 BOM, invisible to the user) is
    skipped, as RFC 8259 allows."""
    text = text.removeprefix("\ufeff")
    return json.loads(text, parse_constant=_refuse_constant, parse_float=_finite_float,
                      parse_int=_float_sized_int, object_pairs_hook=_no_duplicates)


def _where(text, token):
    """'line L column C' of the first value spelled `token` in `text` (after ':', '[' or ',')."""
    match = re.search(r"(?<=[:\[,])\s*(" + re.escape(token) + r")(?![\w.])", text)
    if not match:
        return None
    start = match.start(1)
    line = text.count("\n", 0, start) + 1
    return f"line {line} column {start - (text.rfind(chr(10), 0, start) + 1) + 1}"


def load_document(path, kind: str) -> dict:
    """Parse `path` as strict JSON and validate it against the `kind` schema."""
    path = Path(path)
    regular_file(path, what=f"{kind} file", max_bytes=MAX_DOCUMENT_BYTES)  # no FIFO, device, loop
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:  # the entry is where the first byte that is not UTF-8 stands
        line = exc.object[:exc.start].count(b"\n") + 1
        raise InputError(f"not UTF-8: {exc.reason} (byte {exc.object[exc.start]:#04x})", file=path,
                         entry=f"line {line} (byte offset {exc.start})", fix=f"give a UTF-8 {kind} JSON file") from exc
    except OSError as exc:
        raise InputError(f"cannot read: {exc}", file=path, fix=f"give a UTF-8 {kind} JSON file") from exc
    try:
        doc = strict_json(text)
    except json.JSONDecodeError as exc:
        raise InputError(f"invalid JSON: {exc.msg}", file=path, entry=f"line {exc.lineno} column {exc.colno}",
                         fix="correct the JSON syntax there") from exc
    except _Refused as exc:
        entry = f"key {exc.key!r}" if exc.key is not None else _where(text, exc.token)
        raise InputError(f"invalid JSON: {exc}", file=path, entry=entry,
                         fix="use finite numbers and unique keys (omit an entry to keep its default)") from exc
    except RecursionError:
        raise InputError("invalid JSON: nested too deeply", file=path, fix="flatten the document") from None
    check_document(doc, kind, path)
    return doc


def check_document(doc: dict, kind: str, path) -> None:
    """Validate a parsed document against the `kind` schema; errors name `path` and the entry."""
    validator = jsonschema.Draft202012Validator(schema(kind))
    errors = sorted(validator.iter_errors(doc), key=lambda e: list(map(str, e.absolute_path)))
    raise_if_any([_schema_problem(e, path) for e in errors])


def _schema_problem(error, path) -> InputError:
    entry = ".".join(str(p) for p in error.absolute_path) or "(top level)"
    return InputError(error.message, file=path, entry=entry,
                      fix=_FIXES.get(error.validator, "see the schema in aotv_cosim/schemas"))


def json_value(text: str):
    """A --set value: JSON if it parses (numbers, true/false), else the plain string."""
    try:
        return strict_json(text)
    except (ValueError, RecursionError):  # not JSON, or nested beyond the parser's depth: a text
        return text


def parse_sets(pairs, origin="--set", file=None) -> dict:
    """'comp.var=VALUE' strings -> {'comp.var': value} (VALUE parsed as JSON when it can be);
    file: the scenario the values are for, named in the error. A name given twice is refused
    (which value was meant?)."""
    values = {}
    for text in pairs or ():
        if "=" not in text or "." not in text.split("=", 1)[0]:
            raise InputError(f"cannot read {text!r}: no component.variable before an '='", file=file,
                             entry=origin, fix="write component.variable=value")
        key, raw = text.split("=", 1)
        key = key.strip()
        if key in values:
            raise InputError(f"{key} is given twice", file=file, entry=origin,
                             fix=f"give each value once (keep one {origin} {key}=...)")
        values[key] = json_value(raw.strip())
    return values
