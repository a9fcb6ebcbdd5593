"""Bad input at the edges: paths, XML, SSP annotations, damaged FMUs, output
places, resumed campaigns, schedulers and click's own refusals. Each gives exit status 2 and one
line `error: FILE: ENTRY: CAUSE; FIX`, without a traceback and without hanging."""

import os
import shutil
import zipfile

import pytest

from aotv_cosim.fmu import build as fmu_build
from tests.helpers import NOMINAL, ROOT, WIRING, one_line, run_process, write_json
from tests.model.archives import SSD, rewritten, ssd_text


def in_process(args, timeout=60):
    """Run `python -m aotv_cosim ARGS` (for inputs that would block): (exit status, stderr lines)."""
    done = run_process(*args, timeout=timeout)
    return done.returncode, done.stderr.strip().splitlines()


# ---- paths -------------------------------------------------------------------------------------
def test_symlink_loops_are_one_line(tmp_path):
    loop = tmp_path / "loop.json"
    loop.symlink_to(loop)
    for command in (["validate", loop], ["run", loop, "--out", tmp_path / "o"], ["check", tmp_path]):
        one_line(command, "symlink loop")
    (tmp_path / "sub").mkdir()
    system_loop = write_json(tmp_path / "sub" / "s.json", {"system": str(loop), "stop": 1, "step": 0.1})
    one_line(["validate", system_loop], "system", "symlink loop")
    fmu_loop = tmp_path / "loop.fmu"
    fmu_loop.symlink_to(fmu_loop)
    wiring = write_json(tmp_path / "w.json", {"components": {"a": {"fmu": str(fmu_loop)}}, "connections": []})
    one_line(["validate", wiring], "components.a.fmu", "symlink loop")


@pytest.mark.parametrize("name", ["nul\u0000.json", "x" * 300 + ".json"], ids=["nul", "long"])
def test_unusable_names_in_a_scenario_are_one_line(tmp_path, name):
    scenario = write_json(tmp_path / "s.json", {"system": name, "stop": 1, "step": 0.1})
    one_line(["validate", scenario], "system")
    one_line(["run", scenario, "--out", tmp_path / "o"], "system")


def test_unusable_names_on_the_command_line_are_one_line(tmp_path):
    one_line(["validate", "a\0b.json"], "NUL")
    one_line(["validate", tmp_path / ("x" * 300 + ".json")], "too long")


def test_a_folder_without_permission(tmp_path):
    if os.geteuid() == 0:
        pytest.skip("root reads every folder")
    locked = tmp_path / "locked"
    locked.mkdir()
    shutil.copy(NOMINAL, locked / "s.json")
    locked.chmod(0)
    try:
        one_line(["validate", locked / "s.json"], "permission denied")
        one_line(["check", locked], "permission denied")
    finally:
        locked.chmod(0o700)


def test_a_device_is_refused_before_it_is_read(tmp_path):
    """/dev/zero would be read until memory runs out."""
    one_line(["validate", "/dev/zero"], "not a regular file")
    one_line(["run", "/dev/zero", "--out", tmp_path / "o"], "not a regular file")


@pytest.mark.integration
def test_a_fifo_does_not_hang(tmp_path):
    fifo = tmp_path / "pipe.json"
    os.mkfifo(fifo)
    for args in (["validate", fifo], ["run", fifo, "--out", tmp_path / "o"], ["check", tmp_path]):
        status, lines = in_process(args)
        assert status == 2 and len(lines) == 1 and "not a regular file" in lines[0], (args, status, lines)


@pytest.mark.integration
def test_a_newline_in_a_set_name_stays_on_one_line(tmp_path):
    one_line(["run", NOMINAL, "--set", "vehi\ncle.h0=1", "--out", tmp_path / "o"], "vehi\\ncle")


@pytest.mark.parametrize("args, fragments", [
    (["run", ROOT / "scenarios"], ["scenarios", "SCENARIO", "is a directory"]),
    (["check", "/no/such/folder"], ["/no/such/folder", "does not exist"]),
    (["montecarlo", NOMINAL, "--runs", "0"], ["--runs", "0"]),
    (["run"], ["SCENARIO", "Missing argument"]),
], ids=["folder-as-file", "missing-path", "bad-number", "missing-argument"])
def test_click_refusals_are_one_line(args, fragments):
    one_line(args, *fragments)


# ---- output places -----------------------------------------------------------------------------
@pytest.mark.integration
@pytest.mark.parametrize("where", ["under-a-file", "dev-null"])
def test_unwritable_out_folders(tmp_path, where):
    out = tmp_path / "file.txt" / "out" if where == "under-a-file" else "/dev/null"
    (tmp_path / "file.txt").write_text("x")
    claimed = "cannot make the output folder" if where == "under-a-file" else "not a folder"  # outdir.claimed
    one_line(["run", NOMINAL, "--out", out, "--no-plots"], "--out", claimed)
    one_line(["check", NOMINAL, "--out", out], "--out", "cannot write")
    one_line(["montecarlo", NOMINAL.parent / "montecarlo_robust_density.json", "--runs", "1", "--out", out], "--out",
             claimed)


@pytest.mark.integration
@pytest.mark.parametrize("where", ["under-a-file", "dev-null", "a-folder"])
def test_unwritable_export_targets(tmp_path, where):
    (tmp_path / "file.txt").write_text("x")
    target = {"under-a-file": tmp_path / "file.txt" / "x.ssp", "dev-null": "/dev/null",
              "a-folder": tmp_path}[where]
    one_line(["export-ssp", NOMINAL, "-o", target], "--out",
             "is a directory" if where == "a-folder" else "cannot write")
    assert os.path.exists("/dev/null") and not os.path.isfile("/dev/null")


@pytest.mark.integration
def test_a_read_only_out_folder(tmp_path):
    if os.geteuid() == 0:
        pytest.skip("root writes into read-only folders")
    folder = tmp_path / "ro"
    folder.mkdir()
    folder.chmod(0o500)
    try:
        one_line(["run", NOMINAL, "--out", folder, "--no-plots"], "--out", "permission denied")
        one_line(["export-ssp", NOMINAL, "-o", folder / "x.ssp"], "--out", "permission denied")
    finally:
        folder.chmod(0o700)


# ---- campaigns ---------------------------------------------------------------------------------
@pytest.mark.parametrize("damage", ["campaign-not-json", "campaign-not-object", "rows-bad-number",
                                    "rows-not-utf8"])
def test_a_damaged_campaign_is_refused_on_resume(tmp_path, damage):
    out = tmp_path / "mc"
    out.mkdir()
    (out / "campaign.json").write_text({"campaign-not-json": "{\"runs\": 3,", "campaign-not-object": "[1]"}
                                       .get(damage, "{}"))
    rows = {"rows-bad-number": "run,status,error,steps,x\n0,completed,,10,abc\n",
            "rows-not-utf8": b"run,status\n\xff\xfe\n"}.get(damage)
    if isinstance(rows, bytes):
        (out / "rows.csv").write_bytes(rows)
    elif rows:
        (out / "rows.csv").write_text(rows)
    file = "campaign.json" if damage.startswith("campaign") else "rows.csv"
    one_line(["montecarlo", NOMINAL, "--runs", "2", "--out", out, "--resume"], file, "--resume", "cannot resume")


def test_an_unreachable_scheduler_is_one_line(tmp_path):
    one_line(["montecarlo", NOMINAL, "--runs", "2", "--out", tmp_path / "mc", "--scheduler", "tcp://127.0.0.1:1"],
             "tcp://127.0.0.1:1", "--scheduler", "cannot reach")
    one_line(["montecarlo", NOMINAL, "--runs", "2", "--out", tmp_path / "mc", "--scheduler", "tcp://host:port"],
             "--scheduler", "cannot read the scheduler address")


# ---- SSP archives ------------------------------------------------------------------------------
XXE = """<?xml version="1.0"?>
<!DOCTYPE d [<!ENTITY e SYSTEM "file:///etc/passwd">]>
<d>&e;</d>
"""
LAUGHS = """<?xml version="1.0"?>
<!DOCTYPE d [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;">
<!ENTITY c "&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;"><!ENTITY d "&c;&c;&c;&c;&c;&c;&c;&c;&c;&c;">]>
<d>&d;&d;&d;&d;&d;&d;&d;&d;&d;&d;</d>
"""


@pytest.mark.integration
@pytest.mark.parametrize("text, message", [
    ("<ssd:SystemStructureDescription", "not well-formed XML"),
    (XXE, "document type declaration"),
    (LAUGHS, "document type declaration"),
], ids=["malformed", "external-entity", "entity-expansion"])
def test_bad_ssd_xml_is_one_line(nominal_ssp, tmp_path, text, message):
    ssp = rewritten(nominal_ssp, tmp_path / "bad.ssp", {SSD: text})
    one_line(["validate", ssp], SSD, message)
    one_line(["run", ssp, "--out", tmp_path / "o"], SSD, message)


@pytest.mark.integration
@pytest.mark.parametrize("old, new, message", [
    (' stepSize="', ' stepsize="', "no stepSize"),
    ('<aotv:Experiment ', '<aotv:Other ', "no aotv:Experiment element"),
    (' stepSize="', ' stepSize="fast" x="', "stepSize 'fast' is not a number"),
    ('algorithm="gauss-seidel"', 'algorithm="rk4"', "unknown algorithm 'rk4'"),
    ('<osp:FixedStepAlgorithm ', '<osp:VariableStepAlgorithm ', "no osp:Algorithm/osp:FixedStepAlgorithm"),
], ids=["no-step-size", "no-element", "step-size-fast", "algorithm-rk4", "osp-no-fixed-step"])
def test_bad_step_annotations_are_one_line(nominal_ssp, tmp_path, old, new, message):
    text = ssd_text(nominal_ssp)
    assert old in text
    ssp = rewritten(nominal_ssp, tmp_path / "bad.ssp", {SSD: text.replace(old, new, 1)})
    one_line(["run", ssp, "--out", tmp_path / "o"], message)


# ---- damaged FMUs ------------------------------------------------------------------------------
def _corrupt_member(source, out):
    """A copy of `source` with one byte of its largest member's compressed data flipped."""
    data = bytearray(source.read_bytes())
    with zipfile.ZipFile(source) as archive:
        info = max(archive.infolist(), key=lambda i: i.compress_size)
    start = info.header_offset + 30 + len(info.filename.encode()) + len(info.extra)
    data[start + info.compress_size // 2] ^= 0xFF
    out.write_bytes(bytes(data))
    return out


@pytest.mark.integration
@pytest.mark.parametrize("damage, message", [
    ("corrupt-member", "corrupt"), ("no-binary", "has no binaries/"), ("wrong-identifier", "modelIdentifier 'Wrong'"),
])
def test_damaged_fmus_are_refused_on_load(tmp_path, damage, message):
    source = fmu_build.ensure_fmu("Atmosphere")
    fmu = tmp_path / "Atmosphere.fmu"
    if damage == "corrupt-member":
        _corrupt_member(source, fmu)
    else:
        with zipfile.ZipFile(source) as archive:
            names = archive.namelist()
            text = archive.read("modelDescription.xml").decode()
        if damage == "no-binary":
            rewritten(source, fmu, {n: None for n in names if n.startswith("binaries/")})
        else:
            rewritten(source, fmu, {"modelDescription.xml": text.replace('modelIdentifier="Atmosphere"',
                                                                         'modelIdentifier="Wrong"')})
    wiring = write_json(tmp_path / "w.json", {"components": {"air": {"fmu": "Atmosphere.fmu",
                                                                     "parameters": {"h": 0.0}}},
                                              "connections": []})
    scenario = write_json(tmp_path / "s.json", {"system": "w.json", "stop": 1, "step": 0.5})
    one_line(["validate", wiring], "components.air.fmu", message)
    one_line(["run", scenario, "--out", tmp_path / "o", "--no-plots"], "components.air.fmu", message)


@pytest.mark.integration
def test_the_shipped_fmus_pass_the_member_checks():
    from aotv_cosim.model.fmu_file import read_fmu

    for name in ("Atmosphere", "PointMassVehicle"):
        read_fmu(fmu_build.ensure_fmu(name), file=WIRING, entry=name)


def test_permission_and_read_only_errors_are_named(tmp_path, monkeypatch):
    """What a non-root user meets (root reads and writes everywhere, so the tests above skip):
    EACCES from stat and EROFS or EACCES from creating a file become one InputError each."""
    import errno

    from aotv_cosim import paths
    from aotv_cosim.errors import InputError

    def refuse(code):
        def fail(*args, **kwargs):
            raise OSError(code, os.strerror(code))
        return fail

    monkeypatch.setattr(paths.os, "stat", refuse(errno.EACCES))
    with pytest.raises(InputError, match="cannot be read: permission denied"):
        paths.regular_file(tmp_path / "s.json", what="scenario file")
    monkeypatch.undo()
    for code, cause in ((errno.EROFS, "read-only file system"), (errno.EACCES, "permission denied")):
        monkeypatch.setattr(paths.tempfile, "mkstemp", refuse(code))
        with pytest.raises(InputError, match=f"--out: cannot write an output folder here: {cause}"):
            paths.writable_folder(tmp_path / "out")
        monkeypatch.undo()
