"""Build script: the package is pure Python plus one Cython extension (added with the kernel)."""

from setuptools import setup

setup()
