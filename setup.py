"""Build script: the pure-Python package plus the Cython kernel over the generated C.

The kernel is compiled for the building machine's CPU (``-march=native``); set
``STEWART_MARCH`` (e.g. ``x86-64-v2``) to target another instruction set, as for a
wheel meant for other machines.
"""

import os

import numpy as np
from Cython.Build import cythonize
from setuptools import Extension, setup

kernel = Extension(
    "stewart._kernel",
    sources=["stewart/_kernel.pyx", "generated/stewart_model.c"],
    include_dirs=["generated", np.get_include()],
    define_macros=[("NPY_NO_DEPRECATED_API", "NPY_1_7_API_VERSION")],
    extra_compile_args=["-O3", f"-march={os.environ.get('STEWART_MARCH', 'native')}", "-fopenmp"],
    extra_link_args=["-fopenmp"],
    libraries=["m"],
)

setup(ext_modules=cythonize([kernel], language_level=3))
