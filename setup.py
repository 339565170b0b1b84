"""Build script: the pure-Python package plus the Cython kernel over the generated C.

The kernel is compiled for the building machine's CPU (``-march=native``); set
``STEWART_MARCH`` (e.g. ``x86-64-v2``) to target another instruction set, as for a
wheel meant for other machines. A wheel built here is tagged for the plain platform
(``linux_x86_64``), not ``manylinux``: it claims to run only where it was built.
"""

import os

import numpy as np
from Cython.Build import cythonize
from setuptools import Extension, setup

FLAGS = dict(
    include_dirs=["generated", np.get_include()],
    define_macros=[("NPY_NO_DEPRECATED_API", "NPY_1_7_API_VERSION")],
    extra_compile_args=["-O3", f"-march={os.environ.get('STEWART_MARCH', 'native')}", "-fopenmp"],
    extra_link_args=["-fopenmp"],
    libraries=["m"],
    # Rebuild (build_ext compares times) when the model's header or these flags change.
    depends=["generated/stewart_model.h", "generated/stewart_model.pxd", "setup.py"],
)

extensions = [
    # The model itself: the generated C and its array wrapper.
    Extension("stewart._kernel", sources=["stewart/_kernel.pyx", "generated/stewart_model.c"], **FLAGS),
    # The simulation loop, which calls the model through the kernel's C-level methods.
    Extension("stewart._simulate", sources=["stewart/_simulate.pyx"], **FLAGS),
]

# generated/stewart_model.pxd, the model's Cython declarations, is cimported by stewart/_kernel.pxd.
setup(ext_modules=cythonize(extensions, language_level=3, include_path=["generated"]))
