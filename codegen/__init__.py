"""Code generator for the Stewart platform dynamic model (`python -m codegen`).

`schema` lists the parameters; the derivation (sympy) stands on `graph`, its named
definitions with symbolic forward-mode derivatives, and derives in turn the kinematics
(`kinematics`), the bodies' momenta and generalized forces (`bodies`), the dynamics
(`dynamics`) and their partials (`derivatives`); `model` specifies the public functions
from those kernels.  `emit` turns kernels into C functions, `linsolve` writes the unrolled
solvers, `signatures` the public functions' declarations, `csource` the header, the units
and the dispatch around the fixed C of `templates/`, `pxd` the Cython declarations and
`pymodule` the Python tables.
"""
