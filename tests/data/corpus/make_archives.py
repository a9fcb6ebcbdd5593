"""Write the crafted FMU archives of the corpus (fmus/*.fmu); tests/test_corpus.py runs it first.

Each archive is wrong in one way the wiring loader must report: not a zip, no modelDescription,
broken XML, model exchange only, a member with an absolute path or one climbing out with '..',
no binary, a binary not named after the modelIdentifier, a member inflating 4 MiB of zeros, a
member failing its CRC check, a binary and a modelDescription whose deflate stream is corrupt, a well-formed FMU whose
Integer output cannot feed a Real input, and one with Integer ports (which the master does not exchange); `typed.fmu`
with a parameter of each typed kind (its values are the wiring cases' target) and four copies with one malformed typed
variable: an Enumeration without declaredType, one naming no TypeDefinition, Integer start "abc",
Boolean start "maybe".
"""

import zipfile
from pathlib import Path

from fmpy import platform, sharedLibraryExtension

HERE = Path(__file__).resolve().parent / "fmus"
DATE = (1980, 1, 1, 0, 0, 0)
BINARY = f"binaries/{platform}/Crafted{sharedLibraryExtension}"
"""Where the FMU loader looks for the binary of modelIdentifier Crafted on this platform."""


def description(kind="<CoSimulation modelIdentifier=\"Crafted\"/>", causality="output", type_="Integer",
                extra_input=False):
    start = '<Integer start="0"/>' if type_ == "Integer" else '<Real start="0"/>'
    second = ('\n    <ScalarVariable name="n" valueReference="1" causality="input" variability="discrete">'
              '<Integer start="0"/></ScalarVariable>') if extra_input else ""
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="Crafted" guid="{{00000000-0000-0000-0000-000000000001}}">
  {kind}
  <ModelVariables>
    <ScalarVariable name="count" valueReference="0" causality="{causality}" variability="discrete" initial="exact">{start}</ScalarVariable>{second}
  </ModelVariables>
  <ModelStructure><Outputs><Unknown index="1"/></Outputs></ModelStructure>
</fmiModelDescription>
"""


TYPED_VARIABLES = """
    <ScalarVariable name="n" valueReference="0" causality="parameter" variability="fixed"><Integer start="{n_start}"/></ScalarVariable>
    <ScalarVariable name="flag" valueReference="1" causality="parameter" variability="fixed"><Boolean start="{flag_start}"/></ScalarVariable>
    <ScalarVariable name="mode" valueReference="2" causality="parameter" variability="fixed"><Enumeration {mode_type} start="1"/></ScalarVariable>
    <ScalarVariable name="text" valueReference="3" causality="parameter" variability="fixed"><String start="a"/></ScalarVariable>
    <ScalarVariable name="x" valueReference="4" causality="output" variability="continuous"><Real/></ScalarVariable>
    <ScalarVariable name="label" valueReference="5" causality="output" variability="discrete" initial="exact"><String start="a"/></ScalarVariable>
    <ScalarVariable name="k" valueReference="6" causality="output" variability="discrete" initial="exact"><Integer start="0"/></ScalarVariable>
    <ScalarVariable name="u" valueReference="7" causality="input" variability="continuous"><Real start="0"/></ScalarVariable>
    <ScalarVariable name="m" valueReference="8" causality="input" variability="discrete"><Integer start="0"/></ScalarVariable>"""


def typed_description(n_start="0", flag_start="false", mode_type='declaredType="Modes"'):
    """A co-simulation FMU with an Integer, a Boolean, an Enumeration (type Modes: Hold=1, Ramp=2)
    and a String parameter, Real/String/Integer outputs and Real/Integer inputs; the keyword
    arguments put a malformed start or declared type in."""
    variables = TYPED_VARIABLES.format(n_start=n_start, flag_start=flag_start, mode_type=mode_type)
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="Crafted" guid="{{00000000-0000-0000-0000-000000000002}}">
  <CoSimulation modelIdentifier="Crafted"/>
  <TypeDefinitions><SimpleType name="Modes"><Enumeration><Item name="Hold" value="1"/><Item name="Ramp" value="2"/></Enumeration></SimpleType></TypeDefinitions>
  <ModelVariables>{variables}
  </ModelVariables>
  <ModelStructure><Outputs><Unknown index="5"/><Unknown index="6"/><Unknown index="7"/></Outputs></ModelStructure>
</fmiModelDescription>
"""


def write_zip(name, members):
    with zipfile.ZipFile(HERE / name, "w", zipfile.ZIP_DEFLATED) as archive:
        for member, text in members.items():
            info = zipfile.ZipInfo(member, date_time=DATE)
            info.compress_type = zipfile.ZIP_DEFLATED
            archive.writestr(info, text)


def main():
    HERE.mkdir(exist_ok=True)
    (HERE / "not_a_zip.fmu").write_text("This text file is named .fmu but is no zip archive.\n")
    write_zip("no_model_description.fmu", {"resources/readme.txt": "no modelDescription.xml here\n"})
    write_zip("bad_xml.fmu", {"modelDescription.xml": "<fmiModelDescription fmiVersion=\"2.0\"\n"})
    write_zip("model_exchange.fmu", {"modelDescription.xml": description(
        "<ModelExchange modelIdentifier=\"Crafted\"/>")})
    write_zip("integer_port.fmu", {"modelDescription.xml": description(), BINARY: "not a library\n"})
    write_zip("absolute_member.fmu", {"modelDescription.xml": description(), "/tmp/aotv_evil.txt": "x\n"})
    write_zip("dotdot_member.fmu", {"modelDescription.xml": description(), "resources/../../evil.txt": "x\n"})
    write_zip("no_binary.fmu", {"modelDescription.xml": description()})
    write_zip("wrong_identifier.fmu", {"modelDescription.xml": description(),
                                       BINARY.replace("Crafted", "Other"): "not a library\n"})
    write_zip("inflating.fmu", {"modelDescription.xml": description(), BINARY: "not a library\n",
                                "resources/padding.bin": bytes(4 * 2**20)})
    write_zip("integer_ports.fmu", {"modelDescription.xml": description(extra_input=True),
                                    BINARY: "not a library\n"})
    write_zip("corrupt_member.fmu", {"modelDescription.xml": description(), BINARY: "not a library\n" * 50})
    data = bytearray((HERE / "corrupt_member.fmu").read_bytes())
    at = data.index(BINARY.encode()) + len(BINARY) + 4  # inside the binary's compressed data
    data[at] ^= 0xFF
    (HERE / "corrupt_member.fmu").write_bytes(bytes(data))
    for name, options in (("typed.fmu", {}), ("enumeration_untyped.fmu", {"mode_type": ""}),
                          ("enumeration_unknown_type.fmu", {"mode_type": 'declaredType="Gears"'}),
                          ("integer_start_abc.fmu", {"n_start": "abc"}),
                          ("boolean_start_maybe.fmu", {"flag_start": "maybe"})):
        write_zip(name, {"modelDescription.xml": typed_description(**options), BINARY: "not a library\n"})
    for name, member in (("bad_deflate_binary.fmu", BINARY), ("bad_deflate_description.fmu", "modelDescription.xml")):
        write_zip(name, {"modelDescription.xml": description(), BINARY: "not a library\n" * 50})
        break_deflate(HERE / name, member)


def break_deflate(path, member):
    """Make the first byte of `member`'s compressed data 0xFF: a deflate block of the invalid type
    3, which zlib refuses ('invalid block type') before any CRC is checked."""
    with zipfile.ZipFile(path) as archive:
        info = archive.getinfo(member)
    data = bytearray(path.read_bytes())
    data[info.header_offset + 30 + len(info.filename.encode()) + len(info.extra)] = 0xFF
    path.write_bytes(bytes(data))


if __name__ == "__main__":
    main()
