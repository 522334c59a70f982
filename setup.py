"""Build the Cython core of ``boxtrees``.

Metadata lives in ``pyproject.toml``; this file only declares the extension modules.
The build is portable on every platform: no ``-march`` and no ``-mavx*`` flag. The AVX2 and
AVX-512 kernels of ``boxtrees/_simd.h`` carry their own target attributes, are compiled
only by GCC or clang targeting x86-64 outside macOS and Windows (so on Linux), and run only
when the CPU has AVX2 or AVX-512F (checked at import); builds with MSVC, for macOS (either
architecture) or for ARM have the portable kernels alone. The inner loops are written so
that the compiler can vectorise them at the baseline instruction set.

``BOXTREES_OPTIMIZE`` (default ``-O3``) replaces the optimisation flag of GCC and clang: the
AddressSanitizer test builds with ``-O1``, which compiles in half the time.
"""
import os
import sys

import numpy as np
from Cython.Build import cythonize
from setuptools import Extension, setup

# GCC and clang; MSVC keeps setuptools' own optimisation flag (/O2)
compile_args = ([] if sys.platform == "win32"
                else [os.environ.get("BOXTREES_OPTIMIZE", "-O3"), "-fno-math-errno"])


def _extension(name):
    return Extension(
        f"boxtrees.{name}",
        [f"boxtrees/{name}.pyx"],
        include_dirs=[np.get_include(), "boxtrees"],
        define_macros=[("NPY_NO_DEPRECATED_API", "NPY_1_7_API_VERSION")],
        extra_compile_args=compile_args,
        language="c++",
    )


setup(
    ext_modules=cythonize(
        [_extension(name) for name in ("_builder", "_layout", "_predictor", "_rows", "_splitter")],
        compiler_directives={
            "language_level": 3,
            "boundscheck": False,
            "wraparound": False,
            "cdivision": True,
            "initializedcheck": False,
        },
    ),
)
