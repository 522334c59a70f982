"""Memory safety of the SIMD kernels: no invalid read or write under AddressSanitizer.

valgrind (test_boxtrees_memcheck.py) cannot execute AVX-512 instructions, so under it the
kernels take their AVX2 or portable paths. AddressSanitizer instruments the compiled code instead and
runs natively, SIMD paths included: this test builds boxtrees with it and runs the kernel
driver on that build, then the mutation fuzz tests of test_boxtrees_safety.py. The build (two
minutes of the 2 cores) is kept under build/asan-<digest of the package's sources>/ and
reused while the sources are the same.
"""
import hashlib
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow   # two minutes to build, where no build is kept

ROOT = Path(__file__).resolve().parents[1]


def _libasan():
    """Path of the compiler's AddressSanitizer runtime, or None."""
    if shutil.which("g++") is None:
        return None
    path = subprocess.run(["g++", "-print-file-name=libasan.so"], capture_output=True,
                          text=True).stdout.strip()
    return path if os.path.isabs(path) and os.path.exists(path) else None


_SOURCES = ("*.py", "*.pyx", "*.pxd", "*.h")


def _sanitized_build():
    """The folder of boxtrees built with AddressSanitizer from the current sources: built
    there on first use (the compiler's output in the failure if it fails), reused after."""
    digest = hashlib.sha256()
    for path in sorted(p for pattern in _SOURCES for p in (ROOT / "boxtrees").glob(pattern)):
        digest.update(path.name.encode() + b"\0" + path.read_bytes())
    digest.update((ROOT / "setup.py").read_bytes())
    folder = ROOT / "build" / f"asan-{digest.hexdigest()[:16]}"
    if (folder / "built").exists():
        return folder
    for stale in folder.parent.glob("asan-*"):   # (builds of other sources)
        shutil.rmtree(stale, ignore_errors=True)
    # the generated C++ is copied with its times: cythonize skips sources it is newer than
    shutil.copytree(ROOT / "boxtrees", folder / "boxtrees",
                    ignore=shutil.ignore_patterns("*.so", "__pycache__"))
    shutil.copy(ROOT / "setup.py", folder)
    sanitize = "-fsanitize=address -fno-omit-frame-pointer"
    build = subprocess.run(
        [sys.executable, "setup.py", "build_ext", "--inplace", "--parallel", "2"],
        cwd=folder, capture_output=True, text=True, timeout=900,
        env=dict(os.environ, CPPFLAGS=sanitize, LDFLAGS="-fsanitize=address",
                 BOXTREES_OPTIMIZE="-O1"),
    )
    assert build.returncode == 0, build.stderr[-3000:]
    (folder / "built").touch()
    return folder


@pytest.mark.skipif(_libasan() is None, reason="g++ with AddressSanitizer is not installed")
def test_kernels_have_no_invalid_memory_access_under_address_sanitizer(tmp_path):
    shutil.copytree(_sanitized_build() / "boxtrees", tmp_path / "boxtrees")
    (tmp_path / "tests").mkdir()
    for script in ("conftest.py", "kernel_driver.py", "test_boxtrees_safety.py"):
        shutil.copy(ROOT / "tests" / script, tmp_path / "tests")

    env = dict(os.environ, LD_PRELOAD=_libasan(), ASAN_OPTIONS="detect_leaks=0",
               PYTHONMALLOC="malloc")
    # the kernels on edge cases, then the mutation fuzz tests through the public API; the
    # sanitized build in the working directory shadows the installed one
    for command in ([str(tmp_path / "tests" / "kernel_driver.py")],
                    ["-c", "import boxtrees; print(boxtrees.__file__)"],
                    ["-m", "pytest", "-q", "-p", "no:cacheprovider", "tests/test_boxtrees_safety.py"]):
        result = subprocess.run([sys.executable, *command], cwd=tmp_path, capture_output=True,
                                text=True, timeout=900, env=env)
        assert "AddressSanitizer" not in result.stderr, result.stderr[-3000:]
        assert result.returncode == 0, (result.stdout + result.stderr)[-3000:]
        if command[0] == "-c":
            assert Path(result.stdout.strip()).is_relative_to(tmp_path), result.stdout
    assert "passed" in result.stdout
