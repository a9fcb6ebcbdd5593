"""XML names of the SSP 1.0 formats and the OSP annotation, and schema validation.

The prefixes are fixed on purpose: OSP libcosim's SSD parser matches element names with their
literal prefixes (``ssd:``, ``ssc:``, ``ssv:``, ``osp:``), not by namespace.
"""

from pathlib import Path
from xml.etree import ElementTree

NS = {
    "ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
    "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon",
    "ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues",
    "osp": "http://opensimulationplatform.com/SSP/OSPAnnotations",
    "aotv": "https://github.com/aotv-cosim/aotv-cosim/ssp",
}
for _prefix, _uri in NS.items():
    ElementTree.register_namespace(_prefix, _uri)

OSP_ANNOTATION = "com.opensimulationplatform"
AOTV_ANNOTATION = "org.aotv-cosim.experiment"
SSD_SCHEMA = "SystemStructureDescription.xsd"
SSV_SCHEMA = "SystemStructureParameterValues.xsd"


def q(name: str) -> str:
    """'ssd:System' -> '{namespace}System' (ElementTree's qualified name)."""
    prefix, local = name.split(":")
    return f"{{{NS[prefix]}}}{local}"


def local(tag: str) -> str:
    """'{namespace}System' -> 'System'."""
    return tag.rsplit("}", 1)[-1]


def schema_dir() -> Path:
    """The SSP 1.0 XSD folder that FMPy installs (fmpy/ssp/schema)."""
    import fmpy.ssp

    return Path(fmpy.ssp.__file__).parent / "schema"


def xml_problem(xml: bytes):
    """Why `xml` cannot be read as a plain XML document, else None: not well-formed, or with a
    document type declaration. SSP files need no DTD, and refusing one means no entity, external
    (a local file, a URL) or expanding (billion laughs), is ever resolved."""
    from lxml import etree  # an FMPy dependency

    parser = etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False)
    try:
        tree = etree.fromstring(xml, parser)
    except etree.XMLSyntaxError as exc:
        return f"not well-formed XML: {exc}"
    if tree.getroottree().docinfo.doctype:
        return "has a document type declaration (DTDs and entities are not allowed)"
    return None


def schema_problems(xml: bytes, schema_file: str) -> list:
    """Messages of every violation of the SSP schema `schema_file` by the document `xml`."""
    from lxml import etree  # an FMPy dependency

    schema = etree.XMLSchema(etree.parse(str(schema_dir() / schema_file)))
    if schema.validate(etree.fromstring(xml)):
        return []
    return [f"line {e.line}: {e.message}" for e in schema.error_log]
