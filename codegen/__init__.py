"""Code generator for the Stewart platform dynamic model (`python -m codegen`).

`model` derives the equations (sympy), `emit` turns expressions into C
functions, `csource` holds the fixed C text (header, helpers, public API).
"""
