"""A local campaign worker limits the BLAS libraries it loads after it started, not only those
loaded before: the guidance FMUs import scipy, whose OpenBLAS is a library of its own, in the
worker, at its first run."""

import os
import subprocess
import sys
import textwrap

import pytest

from aotv_cosim.campaigns import backends
from aotv_cosim.campaigns.backends import BLAS_THREAD_VARIABLES
from tests.helpers import ROOT

pytestmark = pytest.mark.integration

PROBE = textwrap.dedent("""
    import json
    import sys

    from aotv_cosim.campaigns import backends


    def blas_after_scipy():
        import scipy.linalg  # noqa: F401 (loads scipy's OpenBLAS in the worker)
        from threadpoolctl import threadpool_info

        return [(info["filepath"], info["num_threads"]) for info in threadpool_info()
                if info["user_api"] == "blas"]


    if __name__ == "__main__":
        assert "scipy" not in sys.modules
        pool = backends._pool(2)
        try:
            print(json.dumps(pool.submit(blas_after_scipy).result()))
        finally:
            pool.shutdown()
""")


@pytest.mark.skipif(backends.usable_cores() < 2, reason="a BLAS share below the default needs 2 cores")
def test_a_worker_limits_the_blas_that_scipy_loads_after_it_started(tmp_path):
    """On a machine whose environment does not set the BLAS thread count, scipy's OpenBLAS loaded
    in a worker of a 2-worker pool runs at most cores / 2 threads (it started one per core: 2 on
    2 cores, and 100 LQR-law runs cost 2.3 times the CPU)."""
    probe = tmp_path / "probe.py"
    probe.write_text(PROBE)
    env = {k: v for k, v in os.environ.items() if k not in BLAS_THREAD_VARIABLES}
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")])
    done = subprocess.run([sys.executable, str(probe)], env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    libraries = __import__("json").loads(done.stdout.splitlines()[-1])
    share = backends.WORKER_BLAS_THREADS
    assert any("scipy" in path for path, _ in libraries), libraries  # scipy's own OpenBLAS is there
    assert all(threads <= share for _, threads in libraries), libraries
