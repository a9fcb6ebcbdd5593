"""Write the crafted FMU archives of the corpus (fmus/*.fmu); tests/test_corpus.py runs it first.

Each archive is wrong in one way the wiring loader must report: not a zip, no modelDescription,
broken XML, model exchange only, a member with an absolute path or one climbing out with '..',
and a well-formed FMU whose Integer output cannot feed a Real input.
"""

import zipfile
from pathlib import Path

from fmpy import platform, sharedLibraryExtension

HERE = Path(__file__).resolve().parent / "fmus"
DATE = (1980, 1, 1, 0, 0, 0)
BINARY = f"binaries/{platform}/Crafted{sharedLibraryExtension}"
"""Where the FMU loader looks for the binary of modelIdentifier Crafted on this platform."""


def description(kind="<CoSimulation modelIdentifier=\"Crafted\"/>", causality="output", type_="Integer"):
    start = '<Integer start="0"/>' if type_ == "Integer" else '<Real start="0"/>'
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="Crafted" guid="{{00000000-0000-0000-0000-000000000001}}">
  {kind}
  <ModelVariables>
    <ScalarVariable name="count" valueReference="0" causality="{causality}" variability="discrete" initial="exact">{start}</ScalarVariable>
  </ModelVariables>
  <ModelStructure><Outputs><Unknown index="1"/></Outputs></ModelStructure>
</fmiModelDescription>
"""


def write_zip(name, members):
    with zipfile.ZipFile(HERE / name, "w", zipfile.ZIP_DEFLATED) as archive:
        for member, text in members.items():
            archive.writestr(zipfile.ZipInfo(member, date_time=DATE), text)


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


if __name__ == "__main__":
    main()
