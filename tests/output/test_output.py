"""Output folders and files: a busy or unusable --out is refused with one exit-2 line before the
run starts; a result file that cannot be written mid-run (disk full) leaves whole rows and a
summary saying 'failed' with the cause, or, if the summary itself cannot be written, one error
line and no empty .part; export-ssp never leaves a truncated archive."""

import contextlib
import errno
import fcntl
import json
import os
import signal
import subprocess

import pytest

from aotv_cosim.output import run_files
from tests.helpers import (NOMINAL, check_whole_rows, cli, relay_scenario, run_process, start_process,
                           wait_for_rows)

pytestmark = pytest.mark.integration


def _one_error(result, *phrases):
    """The one error line (after whatever the progress bar left on that line)."""
    errors = ["error: " + line.split("error: ", 1)[1] for line in result.output.splitlines() if "error: " in line]
    assert len(errors) == 1, result.output
    assert all(p in errors[0] for p in phrases), errors[0]
    return errors[0]


def test_busy_output_folder_is_refused(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    with open(out / ".lock", "w") as held:
        fcntl.flock(held, fcntl.LOCK_EX)
        held.write("4242\n")
        held.flush()
        result = cli("run", relay_scenario(tmp_path, 1.0), "--out", out, "--no-plots")
    assert result.exit_code == 2
    _one_error(result, f"error: {out}: --out: the output folder is in use by another run (pid 4242)",
               "; wait for that run to end or choose another --out")
    assert sorted(p.name for p in out.iterdir()) == [".lock"]


def test_two_runs_into_one_folder_cannot_touch_each_other(tmp_path):
    """The second run is refused at once while the first holds the folder; the first, stopped
    later by SIGTERM, has a whole series. The first is frozen (SIGSTOP) once it is stepping, so it
    holds the folder for as long as the second takes, however slow the machine."""
    scenario = relay_scenario(tmp_path, 1e5)
    out = tmp_path / "out"
    first = start_process("run", scenario, "--out", out, "--no-plots")
    try:
        wait_for_rows(out / "timeseries.csv.part", first)
        first.send_signal(signal.SIGSTOP)
        second = run_process("run", scenario, "--out", out, "--no-plots")
        assert first.poll() is None
        first.send_signal(signal.SIGTERM)  # pending until the first runs again
        first.send_signal(signal.SIGCONT)
        _stdout, stderr = first.communicate(timeout=300)
    finally:
        first.kill()
    assert first.returncode == 143, stderr
    assert second.returncode == 2, second.stderr
    refused = [line for line in second.stderr.strip().splitlines()  # 1e7 rows: a size warning first
               if not line.startswith("warning: ") or "rows of timeseries.csv" not in line]
    assert refused == [
        f"error: {out}: --out: the output folder is in use by another run (pid {first.pid}); "
        "wait for that run to end or choose another --out"]
    check_whole_rows(out)
    assert json.loads((out / "summary.json").read_text())["status"] == "interrupted"


@pytest.mark.parametrize("case", ["file", "devnull", "series-folder", "part-folder", "summary-folder"])
def test_unusable_output_folder_is_refused_before_the_run(tmp_path, case):
    out = tmp_path / "out"
    if case == "file":
        out.write_text("not a folder\n")
        expected = "not a folder: a file is in the way"
    elif case == "devnull":
        out = "/dev/null"
        expected = "not a folder: a file is in the way"
    else:
        name = {"series-folder": "timeseries.csv", "part-folder": "timeseries.csv.part",
                "summary-folder": "summary.json.part"}[case]
        (out / name).mkdir(parents=True)
        expected = f"{name} is a folder left in the way of a result file"
    result = cli("run", relay_scenario(tmp_path, 1.0), "--out", out, "--no-plots")
    assert result.exit_code == 2, result.output
    _one_error(result, f"error: {out}: --out: {expected}")
    assert "steps in" not in result.output  # refused before running


class _FullFile:
    """A file that takes `room` bytes, then writes part of one more chunk and fails with ENOSPC,
    as a full disk does."""

    def __init__(self, f, room):
        self.f, self.room = f, room

    def write(self, data):
        if len(data) <= self.room:
            self.room -= len(data)
            return self.f.write(data)
        if self.room:
            written, self.room = self.f.write(data[:self.room // 2]), 0
            return written
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    def __getattr__(self, name):
        return getattr(self.f, name)


def _fills_up(name, room):
    """A replacement for open() whose file `name` fills up after `room` bytes."""
    def opener(path, *args, **kwargs):
        f = open(path, *args, **kwargs)  # noqa: SIM115 - returned to the code under test, which closes it
        return _FullFile(f, room) if os.path.basename(path) == name else f
    return opener


def test_disk_full_mid_run_keeps_whole_rows_and_a_failed_summary(tmp_path, monkeypatch):
    monkeypatch.setattr(run_files, "open", _fills_up("timeseries.csv.part", 150_000), raising=False)
    out = tmp_path / "out"
    result = cli("run", relay_scenario(tmp_path, 100.0), "--out", out, "--no-plots")
    assert result.exit_code == 1, result.output
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "failed" and summary["stop_reason"] == "output failed"
    assert summary["error"] == (f"{out}: --out: cannot write timeseries.csv.part: No space left on device; "
                                "free space on that disk or choose another --out")
    rows = check_whole_rows(out)
    assert 1000 <= len(rows) < 10001 and len(rows) % 1000 == 0  # whole chunks only
    assert summary["end_time"] == rows[-1][0]


def test_summary_that_cannot_be_written_leaves_no_empty_part(tmp_path, monkeypatch):
    def no_room(path, mode="r", *args, **kwargs):
        if os.path.basename(path) == "summary.json.part":
            open(path, mode).close()  # created, then nothing fits
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return open(path, mode, *args, **kwargs)

    monkeypatch.setattr(run_files, "open", no_room, raising=False)
    out = tmp_path / "out"
    result = cli("run", relay_scenario(tmp_path, 1.0), "--out", out, "--no-plots")
    assert result.exit_code == 1
    _one_error(result, f"error: {out}: --out: cannot write summary.json: No space left on device")
    assert sorted(p.name for p in out.iterdir()) == [".aotv-written", ".lock", "timeseries.csv"]


@contextlib.contextmanager
def _tmpfs(mount, options):
    """A tmpfs mounted at the new folder `mount` with `options` for the `with` (needs root; the test
    is skipped where it cannot be mounted)."""
    mount.mkdir()
    if subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(mount)], capture_output=True).returncode:
        pytest.skip("cannot mount a tmpfs here")
    try:
        yield mount
    finally:
        subprocess.run(["umount", str(mount)], check=True)


def test_real_full_disk(tmp_path):
    """A 256 KiB tmpfs as --out (needs root): whole rows, no .part left, exit 1, the cause told."""
    with _tmpfs(tmp_path / "small", "size=256k") as mount:
        done = run_process("run", relay_scenario(tmp_path, 1000.0), "--out", mount, "--no-plots", timeout=600)
        assert done.returncode == 1, done.stderr
        assert "Traceback" not in done.stderr
        assert not list(mount.glob("*.part"))
        rows = check_whole_rows(mount)
        assert 1000 <= len(rows) < 100001
        if (mount / "summary.json").is_file():
            summary = json.loads((mount / "summary.json").read_text())
            assert summary["status"] == "failed" and "No space left on device" in summary["error"]
        else:
            assert done.stderr.strip().splitlines()[-1].startswith(f"error: {mount}: --out: cannot write summary.json")


def test_read_only_folder_is_refused_before_the_run(tmp_path):
    """A read-only tmpfs as --out (needs root to mount; root ignores permission bits, not this)."""
    with _tmpfs(tmp_path / "ro", "ro,size=64k") as mount:
        result = cli("run", relay_scenario(tmp_path, 1.0), "--out", mount, "--no-plots")
        assert result.exit_code == 2, result.output
        _one_error(result, f"error: {mount}: --out: the output folder is not writable: Read-only file system; "
                           "choose another --out")


def test_export_ssp_leaves_no_truncated_archive(tmp_path, monkeypatch):
    from aotv_cosim.ssp import export

    target = tmp_path / "nominal.ssp"
    assert cli("export-ssp", NOMINAL, "-o", target).exit_code == 0  # an archive of an earlier export
    previous = target.read_bytes()

    def breaks_midway(out, members):
        out.write_bytes(b"PK\x03\x04 truncated")
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(export, "write_reproducible_zip", breaks_midway)
    result = cli("export-ssp", NOMINAL, "-o", target)
    assert result.exit_code == 2
    _one_error(result, f"error: {target}: -o: cannot write the archive: No space left on device")
    assert target.read_bytes() == previous
    assert sorted(p.name for p in tmp_path.iterdir()) == ["nominal.ssp"]
