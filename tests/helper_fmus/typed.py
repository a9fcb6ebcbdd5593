"""Test FMUs with every FMI 2.0 and FMI 3.0 variable type, built by the importer tests.

- `Counter` and `Sink` (pythonfmu): Integer, Boolean and String outputs, inputs and parameters.
- `Modes` (plain C, tests/fmi2_modes.c compiled with gcc): an Enumeration input and output, an
  Integer and a Boolean output, a terminate request, a discarded step and a fixed-step check; its modelDescription
  is written here with the capability flags a test asks for (one binary, several FMUs).
- `Typed3` (plain C, FMI 3.0, tests/helper_fmus/fmi3_typed.c): every FMI 3.0 scalar type in and
  out, a terminate request, a discarded step, FMU states; its modelDescription is written here,
  with an array variable or a clock when a test asks for one (one binary, several FMUs).
"""

import shutil
import subprocess
import textwrap
import zipfile
from pathlib import Path

import fmpy

HERE = Path(__file__).resolve().parent

COUNTER_SOURCE = textwrap.dedent('''
    from pythonfmu import Boolean, Fmi2Causality, Fmi2Slave, Fmi2Variability, Integer, Real, String


    class Counter(Fmi2Slave):
        """Counts steps from `first`, adding `increment` while `enabled`: count (Integer), even
        (Boolean), parity ("even"/"odd", String), level = 0.5 count (Real)."""

        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self.first = 0
            self.increment = 1
            self.enabled = True
            self.label = "n"
            self.count = 0
            self.even = True
            self.parity = "even"
            self.tag = "n=0"
            self.level = 0.0
            self.register_variable(Integer("first", causality=Fmi2Causality.parameter,
                                           variability=Fmi2Variability.fixed))
            self.register_variable(String("label", causality=Fmi2Causality.parameter,
                                          variability=Fmi2Variability.fixed))
            self.register_variable(Integer("increment", causality=Fmi2Causality.input,
                                           variability=Fmi2Variability.discrete))
            self.register_variable(Boolean("enabled", causality=Fmi2Causality.input,
                                           variability=Fmi2Variability.discrete))
            self.register_variable(Integer("count", causality=Fmi2Causality.output,
                                           variability=Fmi2Variability.discrete))
            self.register_variable(Boolean("even", causality=Fmi2Causality.output,
                                           variability=Fmi2Variability.discrete))
            self.register_variable(String("parity", causality=Fmi2Causality.output,
                                           variability=Fmi2Variability.discrete))
            self.register_variable(String("tag", causality=Fmi2Causality.output,
                                           variability=Fmi2Variability.discrete))
            self.register_variable(Real("level", causality=Fmi2Causality.output))

        def enter_initialization_mode(self):
            self.count = self.first
            self._outputs()

        def exit_initialization_mode(self):
            self.count = self.first
            self._outputs()

        def _outputs(self):
            self.even = self.count % 2 == 0
            self.parity = "even" if self.even else "odd"
            self.tag = f"{self.label}={self.count}"
            self.level = 0.5 * self.count

        def do_step(self, current_time, step_size):
            if self.enabled:
                self.count += self.increment
            self._outputs()
            return True
''')

SINK_SOURCE = textwrap.dedent('''
    from pythonfmu import Boolean, Fmi2Causality, Fmi2Slave, Fmi2Variability, Integer, Real, String


    class Sink(Fmi2Slave):
        """Takes an Integer, a Boolean, a String and a Real input; outputs what it holds after
        each step: total (sum of n over the steps), flips (times flag changed), text_length,
        shout (text upper-cased), y (sum of u h, m s)."""

        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self.n = 0
            self.flag = False
            self.text = ""
            self.u = 0.0
            self.total = 0
            self.flips = 0
            self.text_length = 0
            self.shout = ""
            self.y = 0.0
            self._last_flag = False
            self.register_variable(Integer("n", causality=Fmi2Causality.input,
                                           variability=Fmi2Variability.discrete))
            self.register_variable(Boolean("flag", causality=Fmi2Causality.input,
                                           variability=Fmi2Variability.discrete))
            self.register_variable(String("text", causality=Fmi2Causality.input,
                                           variability=Fmi2Variability.discrete))
            self.register_variable(Real("u", causality=Fmi2Causality.input))
            self.register_variable(Integer("total", causality=Fmi2Causality.output,
                                           variability=Fmi2Variability.discrete))
            self.register_variable(Integer("flips", causality=Fmi2Causality.output,
                                           variability=Fmi2Variability.discrete))
            self.register_variable(Integer("text_length", causality=Fmi2Causality.output,
                                           variability=Fmi2Variability.discrete))
            self.register_variable(String("shout", causality=Fmi2Causality.output,
                                           variability=Fmi2Variability.discrete))
            self.register_variable(Real("y", causality=Fmi2Causality.output))

        def exit_initialization_mode(self):
            self._last_flag = self.flag

        def do_step(self, current_time, step_size):
            self.total += self.n
            self.flips += int(self.flag != self._last_flag)
            self._last_flag = self.flag
            self.text_length = len(self.text)
            self.shout = self.text.upper()
            self.y += self.u * step_size
            return True
''')


def build_pythonfmu(folder: Path, name: str, source: str) -> Path:
    """Build the pythonfmu FMU `name` from `source` into `folder`."""
    from pythonfmu.builder import FmuBuilder

    script = folder / f"{name}.py"
    script.write_text(source)
    return Path(FmuBuilder.build_FMU(script, dest=folder / f"{name}.fmu"))


MODES_XML = """<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="Modes" guid="{{5e1d6b1a-0c1e-4a4b-9f1e-6d0de0a00002}}"
  generationTool="aotv-cosim tests" numberOfEventIndicators="0">
  <CoSimulation modelIdentifier="Modes" canHandleVariableCommunicationStepSize="{variable}"
    canBeInstantiatedOnlyOncePerProcess="{once}" canGetAndSetFMUstate="false"/>
  <UnitDefinitions>
    <Unit name="m"><BaseUnit m="1"/></Unit>
    <Unit name="m/s"><BaseUnit m="1" s="-1"/></Unit>
    <Unit name="s"><BaseUnit s="1"/></Unit>
  </UnitDefinitions>
  <TypeDefinitions>
    <SimpleType name="Mode">
      <Enumeration>
        <Item name="Hold" value="1" description="x holds"/>
        <Item name="Ramp" value="2" description="x grows at rate"/>
      </Enumeration>
    </SimpleType>
  </TypeDefinitions>
  {experiment}
  <ModelVariables>
    <ScalarVariable name="mode" valueReference="0" causality="input" variability="discrete">
      <Enumeration declaredType="Mode" start="1"/></ScalarVariable>
    <ScalarVariable name="rate" valueReference="1" causality="parameter" variability="fixed" initial="exact">
      <Real unit="m/s" start="1"/></ScalarVariable>
    <ScalarVariable name="terminate_at" valueReference="2" causality="parameter" variability="fixed" initial="exact">
      <Real unit="s" start="1e9"/></ScalarVariable>
    <ScalarVariable name="x" valueReference="3" causality="output" variability="continuous" initial="exact">
      <Real unit="m" start="0"/></ScalarVariable>
    <ScalarVariable name="mode_out" valueReference="4" causality="output" variability="discrete" initial="calculated">
      <Enumeration declaredType="Mode"/></ScalarVariable>
    <ScalarVariable name="ticks" valueReference="5" causality="output" variability="discrete" initial="calculated">
      <Integer/></ScalarVariable>
    <ScalarVariable name="ramping" valueReference="6" causality="output" variability="discrete" initial="calculated">
      <Boolean/></ScalarVariable>
    <ScalarVariable name="fixed_step" valueReference="7" causality="parameter" variability="fixed" initial="exact">
      <Real unit="s" start="0"/></ScalarVariable>
    <ScalarVariable name="discard_at" valueReference="8" causality="parameter" variability="fixed" initial="exact">
      <Real unit="s" start="1e9"/></ScalarVariable>
    <ScalarVariable name="bias" valueReference="9" causality="input" variability="continuous">
      <Real unit="m/s" start="0"/></ScalarVariable>
  </ModelVariables>
  <ModelStructure>
    <Outputs>
      <Unknown index="4" dependencies=""/>
      <Unknown index="5" dependencies="1"/>
      <Unknown index="6" dependencies=""/>
      <Unknown index="7" dependencies="1"/>
    </Outputs>
    <InitialUnknowns>
      <Unknown index="5" dependencies="1"/>
      <Unknown index="6" dependencies=""/>
      <Unknown index="7" dependencies="1"/>
    </InitialUnknowns>
  </ModelStructure>
</fmiModelDescription>
"""


def compile_modes(folder: Path) -> Path:
    """tests/fmi2_modes.c compiled into a shared library (with FMPy's FMI 2.0 headers)."""
    headers = Path(fmpy.__file__).parent / "c-code"
    library = folder / f"Modes{fmpy.sharedLibraryExtension}"
    subprocess.run(["gcc", "-shared", "-fPIC", "-O1", "-I", str(headers), "-o", str(library),
                    str(HERE / "fmi2_modes.c"), "-lm"], check=True)
    return library


def modes_fmu(path: Path, library: Path, variable=True, once=False, experiment=None) -> Path:
    """An FMU of the Modes binary with these capability flags and DefaultExperiment
    (`experiment`: {"startTime": .., "stopTime": .., "stepSize": ..} or None)."""
    attributes = " ".join(f'{k}="{v}"' for k, v in (experiment or {}).items())
    xml = MODES_XML.format(variable=str(variable).lower(), once=str(once).lower(),
                           experiment=f"<DefaultExperiment {attributes}/>" if experiment else "")
    with zipfile.ZipFile(path, "w") as archive:
        archive.writestr("modelDescription.xml", xml)
        archive.write(library, f"binaries/{fmpy.platform}/{library.name}")
    return path


def have_gcc() -> bool:
    return shutil.which("gcc") is not None


TYPED3_TOKEN = "{5e1d6b1a-0c1e-4a4b-9f1e-6d0de0a00003}"
"""The instantiation token compiled into fmi3_typed.c."""

TYPED3_PAIRS = [("f32", "Float32", 10, 'start="0"'), ("i8", "Int8", 12, 'start="0"'), ("u8", "UInt8", 14, 'start="0"'),
                ("i16", "Int16", 16, 'start="0"'), ("u16", "UInt16", 18, 'start="0"'),
                ("i32", "Int32", 20, 'start="0"'), ("u32", "UInt32", 22, 'start="0"'),
                ("i64", "Int64", 24, 'start="0"'), ("u64", "UInt64", 26, 'start="0"'),
                ("flag", "Boolean", 28, 'start="false"'), ("text", "String", 30, ""), ("blob", "Binary", 32, "")]
"""(name stem, FMI 3.0 type, value reference of the input, start attribute): <stem>_in and
<stem>_out (value reference + 1) of Typed3."""


def typed3_xml(token=TYPED3_TOKEN, extra="", experiment=None, variable=True, state=True, once=False) -> str:
    """Typed3's modelDescription; `extra`: more ModelVariables elements (an array, a clock);
    variable, state, once: canHandleVariableCommunicationStepSize, canGetAndSetFMUState,
    canBeInstantiatedOnlyOncePerProcess."""
    variables = []
    for stem, kind, vr, start in TYPED3_PAIRS:
        child = '<Start value=""/>' if kind in ("String", "Binary") else ""
        variables.append(f'<{kind} name="{stem}_in" valueReference="{vr}" causality="input" {start}>{child}</{kind}>')
        variables.append(f'<{kind} name="{stem}_out" valueReference="{vr + 1}" causality="output"/>')
    outputs = "\n    ".join(f'<Output valueReference="{vr + 1}" dependencies="{vr}"/>' for _, _, vr, _ in TYPED3_PAIRS)
    initial = "\n    ".join(f'<InitialUnknown valueReference="{vr + 1}" dependencies="{vr}"/>'
                            for _, _, vr, _ in TYPED3_PAIRS)
    attributes = " ".join(f'{k}="{v}"' for k, v in (experiment or {}).items())
    declared = "\n    ".join(variables)
    default = f"<DefaultExperiment {attributes}/>" if experiment else ""
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="3.0" modelName="Typed3" instantiationToken="{token}"
  generationTool="aotv-cosim tests">
  <CoSimulation modelIdentifier="Typed3" canHandleVariableCommunicationStepSize="{str(variable).lower()}"
    canGetAndSetFMUState="{str(state).lower()}" canBeInstantiatedOnlyOncePerProcess="{str(once).lower()}"/>
  <UnitDefinitions>
    <Unit name="m"><BaseUnit m="1"/></Unit>
    <Unit name="m/s"><BaseUnit m="1" s="-1"/></Unit>
    <Unit name="s"><BaseUnit s="1"/></Unit>
  </UnitDefinitions>
  <TypeDefinitions>
    <Float64Type name="Length" unit="m"/>
    <EnumerationType name="Mode">
      <Item name="Hold" value="1"/>
      <Item name="Ramp" value="2"/>
    </EnumerationType>
  </TypeDefinitions>
  {default}
  <ModelVariables>
    <Float64 name="time" valueReference="0" causality="independent" variability="continuous"/>
    <Float64 name="rate" valueReference="1" causality="parameter" variability="fixed" unit="m/s" start="1"/>
    <Float64 name="x" valueReference="2" causality="output" declaredType="Length" initial="exact" start="0"/>
    <Float64 name="u" valueReference="3" causality="input" unit="m" start="0"/>
    <Float64 name="y" valueReference="4" causality="output" unit="m"/>
    <Float64 name="terminate_at" valueReference="5" causality="parameter" variability="fixed" unit="s" start="1e9"/>
    <Float64 name="discard_at" valueReference="6" causality="parameter" variability="fixed" unit="s" start="1e9"/>
    {declared}
    <Enumeration name="mode_in" declaredType="Mode" valueReference="34" causality="input" start="1"/>
    <Enumeration name="mode_out" declaredType="Mode" valueReference="35" causality="output"/>
    <Int32 name="steps" valueReference="36" causality="output" variability="discrete" initial="exact" start="0"/>
    {extra}
  </ModelVariables>
  <ModelStructure>
    <Output valueReference="2" dependencies=""/>
    <Output valueReference="4" dependencies="3"/>
    {outputs}
    <Output valueReference="35" dependencies="34"/>
    <Output valueReference="36" dependencies=""/>
    <InitialUnknown valueReference="4" dependencies="3"/>
    {initial}
    <InitialUnknown valueReference="35" dependencies="34"/>
  </ModelStructure>
</fmiModelDescription>
"""


ARRAY3 = '<Float64 name="vec" valueReference="40" causality="output"><Dimension start="3"/></Float64>'
"""An FMI 3.0 array output (refused by the master)."""
CLOCK3 = ('<Clock name="tick" valueReference="41" causality="input" intervalVariability="constant" '
          'intervalDecimal="1"/>')
"""An FMI 3.0 input clock (refused by the master)."""


def compile_typed3(folder: Path) -> Path:
    """tests/helper_fmus/fmi3_typed.c compiled into a shared library (with FMPy's FMI 3.0 headers)."""
    headers = Path(fmpy.__file__).parent / "c-code"
    library = folder / f"Typed3{fmpy.sharedLibraryExtension}"
    subprocess.run(["gcc", "-shared", "-fPIC", "-O1", "-I", str(headers), "-o", str(library),
                    str(HERE / "fmi3_typed.c"), "-lm"], check=True)
    return library


def typed3_fmu(path: Path, library: Path, **xml) -> Path:
    """An FMU of the Typed3 binary with the modelDescription `typed3_xml(**xml)`."""
    with zipfile.ZipFile(path, "w") as archive:
        archive.writestr("modelDescription.xml", typed3_xml(**xml))
        archive.write(library, f"binaries/{fmpy.platform_tuple}/{library.name}")
    return path
