"""Memory safety of the Cython kernels: no invalid read or write under valgrind's memcheck.

A heap overflow of a few bytes does not fail any functional test, yet corrupts the heap and
crashes a long run much later; memcheck sees it at the faulty store.
"""
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow   # the kernels under valgrind: about 40 s

SCRIPT = Path(__file__).with_name("kernel_driver.py")
# a valgrind error report: its kind, then the call stack, up to the next blank report line
ERROR = re.compile(r"==\d+== (Invalid (?:read|write)[^\n]*|[^\n]*uninitialised[^\n]*)\n((?:==\d+== {3,}[^\n]*\n)+)")


@pytest.mark.skipif(shutil.which("valgrind") is None, reason="valgrind is not installed")
def test_cython_kernels_have_no_invalid_memory_access():
    env = dict(os.environ, PYTHONMALLOC="malloc")
    result = subprocess.run(
        ["valgrind", "-q", "--num-callers=8", sys.executable, str(SCRIPT)],
        capture_output=True, text=True, env=env, timeout=600,
    )
    assert result.returncode == 0, result.stderr[-3000:]
    assert "kernels ok" in result.stdout
    # the dynamic loader and CPython itself have known, harmless reports: keep ours only
    ours = [kind + "\n" + stack for kind, stack in ERROR.findall(result.stderr) if "boxtrees" in stack]
    assert not ours, "\n\n".join(ours)
