"""Symbol definitions and output expressions -> straight-line C99 functions over a block of
states.

Pure code generation, no physics: prune the definitions the outputs do not
need, run `sympy.cse` (order='none') over the remaining definitions and the
outputs together, and print one constant per definition or common subexpression -- a
`stewart_vd` (one state per lane) where it depends on the state, a `double` where it
depends on the parameters alone -- with a C99 printer that writes small integer powers as
products.  The model's single-state functions run the same code on one state, so a state
gives the same bits alone as in any lane of any block.
"""

from dataclasses import dataclass

import sympy as sp
from sympy.printing.c import C99CodePrinter
from sympy.printing.precedence import PRECEDENCE


class _Printer(C99CodePrinter):
    """C99 printer writing b**n (|n| <= 4) as products instead of pow(), parenthesized; an
    expression over the `varying` symbols (one value per lane) is a `stewart_vd`, with sqrt,
    sin, cos and tanh of it as the lane-wise `vsqrt`, `vsin`, `vcos`, `vtanh`
    (codegen/templates/lanes.c); the parameters stay scalars, broadcast by the arithmetic
    operators."""

    def __init__(self, varying):
        super().__init__()
        self.varying = varying

    def _varies(self, expr):
        return bool(expr.free_symbols & self.varying)

    def _print_Pow(self, expr):
        if expr.exp in (sp.S.Half, -sp.S.Half) and self._varies(expr.base):
            root = f'vsqrt({self._print(expr.base)})'
            return root if expr.exp > 0 else f'1.0/{root}'
        base, exp = expr.as_base_exp()
        if exp.is_Integer and 1 <= abs(int(exp)) <= 4:
            factor = self.parenthesize(base, PRECEDENCE['Mul'], strict=True)
            product = '*'.join([factor] * abs(int(exp)))
            # parenthesized: the Mul printer writes a denominator b**n as '/' + _print_Pow
            return f'({product})' if exp > 0 else f'1.0/({product})'
        return super()._print_Pow(expr)

    def _print_Function(self, expr):
        if isinstance(expr, (sp.sin, sp.cos, sp.tanh)) and self._varies(expr):
            return f'v{type(expr).__name__}({self._print(expr.args[0])})'
        return super()._print_Function(expr)

    _print_sin = _print_cos = _print_tanh = _print_Function


@dataclass
class EmittedKernel:
    name: str
    source: str       # C source of `void vkernel_<name>(...)`
    ops: int          # sympy count_ops of the cse output
    declaration: str  # its prototype


def _prune(defs, outputs):
    """Definitions (in order) that the outputs depend on."""
    needed = set().union(*[e.free_symbols for e in outputs])
    kept = []
    for sym, expr in reversed(defs):
        if sym in needed:
            kept.append((sym, expr))
            needed |= expr.free_symbols
    kept.reverse()
    return kept


def _statements(defs, outputs):
    """cse over definitions and outputs; returns (statements, outputs, ops).

    Statements are (symbol, expression) in dependency order: each common
    subexpression is placed right before the first statement that uses it.
    """
    syms = [s for s, _ in defs]
    repl, reduced = sp.cse([e for _, e in defs] + outputs,
                           symbols=sp.numbered_symbols('c'), order='none')
    ops = sum(sp.count_ops(e) for _, e in repl) + sum(sp.count_ops(e) for e in reduced)
    pending = dict(repl)
    index = {s: k for k, (s, _) in enumerate(repl)}
    statements = []

    def place(expr):
        for s in sorted(expr.free_symbols & pending.keys(), key=index.__getitem__):
            if s in pending:
                sub = pending.pop(s)
                place(sub)
                statements.append((s, sub))

    for sym, expr in zip(syms, reduced[:len(syms)]):
        place(expr)
        statements.append((sym, expr))
    out = reduced[len(syms):]
    for expr in out:
        place(expr)
    return statements, out, ops


def emit_kernel(kernel, param_members):
    """C source of `void vkernel_<name>(...)` for a `model.KernelSpec`, and its prototype
    (kernels are shared between the model's units): the kernel over a block of STEWART_LANES
    states, every quantity that depends on the state a `stewart_vd` (one state per lane;
    inputs and outputs are arrays of them, entry k of the states in element k), the
    parameters and what depends on them alone computed once, as doubles.

    `param_members` maps parameter symbols to C expressions reading them from
    `const stewart_params *p`.  A kernel with `lanes` > 1 is a loop over its lanes with
    interleaved arrays (entry k of lane i at k * lanes + i; its `shared` inputs whole).
    """
    outputs = [sp.sympify(e) for _, exprs in kernel.outputs for e in exprs]
    statements, reduced, ops = _statements(_prune(kernel.graph.defs, outputs), outputs)
    used = set().union(*[e.free_symbols for _, e in statements], *[e.free_symbols for e in reduced])
    varying = {s for _, syms in kernel.inputs for s in syms}
    printer = _Printer(varying)
    lanes = kernel.lanes
    at = (lambda k: f'[{k}]') if lanes == 1 else (lambda k: f'[{k} * {lanes} + lane]')
    args = (['const stewart_params *p'] + [f'const stewart_vd *{name}' for name, _ in kernel.inputs]
            + [f'stewart_vd *{name}' for name, _ in kernel.outputs])
    signature = f'void vkernel_{kernel.name}({", ".join(args)})'
    lines = [f'/* {kernel.doc} */', signature, '{']
    lines += [f'    const double {s.name} = p->{member};' for s, member in param_members if s in used]
    if not any(s in used for s, _ in param_members):
        lines.append('    (void)p;')
    indent = '    '
    if lanes > 1:
        lines += ['    int lane;', f'    for (lane = 0; lane < {lanes}; ++lane) {{']
        indent = '        '
    for name, syms in kernel.inputs:
        index = (lambda k: f'[{k}]') if name in kernel.shared else at
        lines += [f'{indent}const stewart_vd {s.name} = {name}{index(k)};' for k, s in enumerate(syms) if s in used]
    for s, e in statements:
        vary = bool(e.free_symbols & varying)
        if vary:
            varying.add(s)
        lines.append(f'{indent}const {"stewart_vd" if vary else "double"} {s.name} = {printer.doprint(e)};')
    k = 0
    for name, exprs in kernel.outputs:
        for j in range(len(exprs)):
            e = reduced[k]
            value = printer.doprint(e)
            lines.append(f'{indent}{name}{at(j)} = {value if e.free_symbols & varying else f"vsplat({value})"};')
            k += 1
    if lanes > 1:
        lines.append('    }')
    lines.append('}')
    return EmittedKernel(kernel.name, '\n'.join(lines) + '\n', ops, signature)
