"""Reading scenario and wiring files: strict JSON, then the shipped JSON schemas.

Files are data: nothing in them is evaluated. NaN and Infinity literals, which Python's json
module would accept, are refused, as are duplicate keys.
"""

import json
from importlib import resources
from pathlib import Path

import jsonschema

from aotv_cosim.errors import InputError, raise_if_any

SCHEMAS = {"wiring": "wiring.schema.json", "scenario": "scenario.schema.json",
           "compare": "compare.schema.json"}

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
    text = resources.files("aotv_cosim").joinpath("schemas", SCHEMAS[kind]).read_text()
    return json.loads(text)


def _refuse_constant(name):
    raise ValueError(f"{name} is not a finite number")


def _no_duplicates(pairs):
    keys = [k for k, _ in pairs]
    duplicated = sorted({k for k in keys if keys.count(k) > 1})
    if duplicated:
        raise ValueError(f"duplicate key {duplicated[0]!r}")
    return dict(pairs)


def load_document(path, kind: str) -> dict:
    """Parse `path` as strict JSON and validate it against the `kind` schema."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise InputError("file not found", file=path, fix=f"give the path of an existing {kind} file")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read: {exc}", file=path, fix=f"give a UTF-8 {kind} JSON file")
    try:
        doc = json.loads(text, parse_constant=_refuse_constant, object_pairs_hook=_no_duplicates)
    except json.JSONDecodeError as exc:
        raise InputError(f"invalid JSON: {exc.msg}", file=path, entry=f"line {exc.lineno} column {exc.colno}",
                         fix="correct the JSON syntax there")
    except ValueError as exc:
        raise InputError(f"invalid JSON: {exc}", file=path,
                         fix="use finite numbers and unique keys (omit an entry to keep its default)")
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
        return json.loads(text, parse_constant=_refuse_constant)
    except ValueError:
        return text
