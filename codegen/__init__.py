"""Code generator for the Stewart platform dynamic model (`python -m codegen`).

`schema` lists the parameters, `model` derives the equations (sympy) and specifies
the public functions, `emit` turns expressions into C functions, `linsolve` writes
the unrolled solvers, `csource` writes the header and the public functions around
the fixed C of `templates/`, and `pxd` the Cython declarations.
"""
