"""Symbol definitions and output expressions -> straight-line C99 functions over a block of
states.

Pure code generation, no physics: prune the definitions the outputs do not
need, run symengine's cse over the remaining definitions and the outputs
together (the sympy expressions converted to symengine), and print one constant per
definition or common subexpression -- a `stewart_vd` (one state per lane) where it depends
on the state, a `double` where it depends on the parameters alone -- with a printer of the
few node types the model uses (Add, Mul, Pow, Symbol, numbers, sin, cos, tanh), in the
order of symengine's arguments, writing small integer powers as products.  The model's
single-state functions run the same code on one state, so a state gives the same bits
alone as in any lane of any block.
"""

from dataclasses import dataclass

import symengine as se
import sympy as sp

# Operator precedences as sympy's printers use them: an operand is parenthesized when its
# precedence is at most its operator's (below it when strict).
_ADD, _MUL, _POW, _FUNC, _ATOM = 40, 50, 60, 70, 1000


class _Expr:
    """An expression of the cse output: the symengine `value`, the sympy symbols it reads
    (`free_symbols`) and `symbols`, the sympy symbol of each symengine one (shared by a
    kernel's expressions)."""
    __slots__ = ('value', 'free_symbols', 'symbols')

    def __init__(self, value, symbols):
        self.value = value
        self.symbols = symbols
        self.free_symbols = {symbols[s] for s in value.free_symbols}


def _precedence(e):
    if e.is_Add:
        return _ADD
    if e.is_Mul:
        return _ADD if e.args[0].is_Number and e.args[0].is_negative else _MUL
    if e.is_Pow:
        return _POW
    if e.is_Number:
        if e.is_negative:
            return _ADD
        return _ATOM if e.is_Integer else _MUL
    if e.is_Function:
        return _FUNC
    return _ATOM


class _Printer:
    """C99 printer of cse output (`_Expr`) writing b**n (|n| <= 4) as products instead of pow(),
    parenthesized.  An expression over the `varying` symbols (one value per lane) is a
    `stewart_vd`, with sqrt, sin, cos and tanh of it as the lane-wise `vsqrt`, `vsin`, `vcos`,
    `vtanh` (codegen/templates/lanes.c); the parameters stay scalars, broadcast by the
    arithmetic operators.  It prints sums and products in the order of symengine's arguments
    and writes them as sympy's C99 printer does (a negative term as a subtraction, a
    product's factors with negative exponents as a denominator)."""

    #: The functions it prints, by symengine function name.
    functions = ('sin', 'cos', 'tanh')

    def __init__(self, varying):
        self.varying = varying

    def doprint(self, expr):
        self._symbols = expr.symbols
        return self._print(expr.value)

    def _paren(self, e, level, strict=False):
        p = _precedence(e)
        return f'({self._print(e)})' if p < level or (not strict and p == level) else self._print(e)

    def _print(self, e):
        if e.is_Symbol:
            return self._symbols[e].name
        if e.is_Add:
            return self._print_Add(e)
        if e.is_Mul:
            return self._print_Mul(e)
        if e.is_Pow:
            return self._print_Pow(e.args[0], e.args[1])
        if e.is_Integer:
            return str(int(e))
        if e.is_Rational:
            p, q = e.get_num_den()
            return f'{int(p)}.0/{int(q)}.0'
        if e.is_Function and type(e).__name__ in self.functions and len(e.args) == 1:
            return self._print_Function(e)
        raise NotImplementedError(f'no C for {type(e).__name__}: {e}')

    def _varies(self, expr):
        return any(self._symbols[s] in self.varying for s in expr.free_symbols)

    def _print_Function(self, e):
        return f'{"v" if self._varies(e) else ""}{type(e).__name__}({self._print(e.args[0])})'

    def _print_Add(self, e):
        parts = []
        for term in e.args:
            t = self._print(term)
            if t.startswith('-') and not term.is_Add:
                sign, t = '-', t[1:]
            else:
                sign = '+'
            parts += [sign, f'({t})' if _precedence(term) < _ADD or term.is_Add else t]
        sign = parts.pop(0)
        return ('' if sign == '+' else sign) + ' '.join(parts)

    def _print_Mul(self, e):
        args = list(e.args)
        sign = ''
        if args[0].is_Number and args[0].is_negative:
            sign = '-'
            args[0] = -args[0]
            if args[0] == 1:
                del args[0]
        num, den = [], []  # factors; denominator: (base, positive exponent)
        for a in args:
            if a.is_Pow and a.args[1].is_Rational and a.args[1].is_negative:
                den.append((a.args[0], -a.args[1]))
            else:
                num.append(a)
        num = num or [se.Integer(1)]
        if len(num) == 1 and sign == '-':
            a_str = [self._paren(num[0], (_POW + _MUL) / 2)]
        else:
            a_str = [self._paren(a, _MUL) for a in num]
        b_str = [self._print(b) if x == 1 and _precedence(b) > _MUL else
                 f'({self._print(b)})' if x == 1 else self._print_Pow(b, x) for b, x in den]
        if not den:
            return sign + '*'.join(a_str)
        if len(den) == 1:
            return sign + '*'.join(a_str) + '/' + b_str[0]
        return sign + '*'.join(a_str) + f'/({"*".join(b_str)})'

    def _print_Pow(self, base, exp):
        if exp in (se.Rational(1, 2), se.Rational(-1, 2)) and self._varies(base):
            root = f'vsqrt({self._print(base)})'
            return root if exp.is_positive else f'1.0/{root}'
        if exp.is_Integer and 1 <= abs(int(exp)) <= 4:
            factor = self._paren(base, _MUL, strict=True)
            product = '*'.join([factor] * abs(int(exp)))
            # parenthesized: the Mul printer writes a denominator b**n as '/' + _print_Pow
            return f'({product})' if exp.is_positive else f'1.0/({product})'
        if exp == se.Rational(1, 2):
            return f'sqrt({self._print(base)})'
        return f'pow({self._print(base)}, {self._print(exp)})'


@dataclass
class EmittedKernel:
    name: str
    source: str       # C source of `void vkernel_<name>(...)`
    ops: int          # operations of the cse output (_count_ops)
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


def _negative(e):
    """Whether the printers write `e` with a leading minus (a negative number or coefficient)."""
    return e.is_Number and e.is_negative or e.is_Mul and e.args[0].is_Number and e.args[0].is_negative


def _count_ops(e):
    """The operations of `e` as the printers write it in C: its binary +, -, *, /, its
    negations and its calls (sqrt, pow, sin, ...); a power with a small integer exponent
    is the multiplications of its product, and constant rationals (p.0/q.0) count none."""
    n = 0
    stack = [e]
    while stack:
        a = stack.pop()
        if a.is_Add:
            n += len(a.args) - 1 + _negative(a.args[0])
            for t in a.args:  # a negative term's sign is its + or -
                stack.append(-t if _negative(t) else t)
        elif a.is_Mul:
            args = a.args
            if _negative(args[0]):
                n += 1
                if args[0] == -1:
                    args = args[1:]
            denominator = False
            for f in args:
                if f.is_Pow and f.args[1].is_Rational and f.args[1].is_negative:
                    denominator = True
                    stack.append(f.args[0] ** -f.args[1])
                else:
                    stack.append(f)
            # a*b/(c*d); 1/(c*d) without a numerator
            n += len(args) - 1 + (denominator and all(
                f.is_Pow and f.args[1].is_Rational and f.args[1].is_negative for f in args))
        elif a.is_Pow:
            x = a.args[1]
            if x.is_Integer and abs(int(x)) <= 4:
                n += abs(int(x)) - 1 + x.is_negative  # the product, and 1.0/(...)
            else:
                n += 1 + (x == se.Rational(-1, 2))  # sqrt or pow(), with 1.0/ in the vector kernel
            stack.append(a.args[0])
        elif a.is_Function:
            n += 1
            stack.extend(a.args)
    return n


#: The symengine functions of the sympy ones the model uses.
_FUNCTIONS = {sp.sin: se.sin, sp.cos: se.cos, sp.tanh: se.tanh}


def _symengine_symbol(s, symbols):
    """The symengine symbol of sympy symbol `s`, recorded in `symbols` (symengine -> sympy)."""
    r = se.Symbol(s.name)
    if symbols.setdefault(r, s) != s:
        raise ValueError(f'two symbols named {s.name}')
    return r


def _symengine(exprs, symbols):
    """sympy expressions -> symengine ones (what `symengine.sympify` gives, faster: each
    distinct subexpression converted once), the symbols recorded in `symbols`."""
    memo = {}

    def convert(e):
        r = memo.get(e)
        if r is None:
            if e.is_Symbol:
                r = _symengine_symbol(e, symbols)
            elif e.is_Add:
                r = se.Add(*map(convert, e.args))
            elif e.is_Mul:
                r = se.Mul(*map(convert, e.args))
            elif e.is_Pow:
                r = se.Pow(convert(e.base), convert(e.exp))
            elif e.is_Integer:
                r = se.Integer(int(e))
            elif e.is_Rational:
                r = se.Rational(int(e.p), int(e.q))
            elif type(e) in _FUNCTIONS:
                r = _FUNCTIONS[type(e)](*map(convert, e.args))
            else:
                r = se.sympify(e)
            memo[e] = r
        return r

    return [convert(e) for e in exprs]


def _statements(defs, outputs):
    """cse over definitions and outputs; returns (statements, outputs, ops).

    Statements are (symbol, expression) in dependency order: each common
    subexpression, a symbol c<k>, is placed right before the first statement that
    uses it.  The expressions are `_Expr`s; `ops` counts their operations (`_count_ops`).
    """
    syms = [s for s, _ in defs]
    symbols = {}
    converted = _symengine([e for _, e in defs] + outputs, symbols)
    for s in syms:
        _symengine_symbol(s, symbols)
    names = {s.name for s in symbols.values()}
    repl, reduced = se.cse(converted)
    # symengine names the subexpressions x0, x1, ...: they must be new names, and are printed c0, c1, ...
    taken = [str(s) for s, _ in repl if s in symbols]
    if taken:
        raise ValueError(f'cse symbols {taken} are names of the model')
    fresh = (f'c{k}' for k in range(len(names) + len(repl) + 1))
    fresh = (n for n in fresh if n not in names)
    for s, _ in repl:
        symbols[s] = sp.Symbol(next(fresh))
    repl = [(symbols[s], _Expr(e, symbols)) for s, e in repl]
    reduced = [_Expr(e, symbols) for e in reduced]
    ops = sum(_count_ops(e.value) for _, e in repl) + sum(_count_ops(e.value) for e in reduced)
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


def emit_kernel(kernel, param_members, params_type='stewart_params'):
    """C source of `void vkernel_<name>(...)` for a `graph.KernelSpec`, and its prototype
    (kernels are shared between the model's units): the kernel over a block of STEWART_LANES
    states, every quantity that depends on the state a `stewart_vd` (one state per lane;
    inputs and outputs are arrays of them, entry k of the states in element k), the
    parameters and what depends on them alone computed once, as doubles.

    `param_members` maps parameter symbols to C expressions reading them from
    `const <params_type> *p` (`stewart_params`, or the rotary family's
    `stewart_rotary_params`).  A kernel with `lanes` > 1 is a loop over its lanes with
    interleaved arrays (entry k of lane i at k * lanes + i; its `shared` inputs whole, its `sums`
    outputs summed over the lanes).
    """
    outputs = [sp.sympify(e) for _, exprs in kernel.outputs for e in exprs]
    statements, reduced, ops = _statements(_prune(kernel.graph.defs, outputs), outputs)
    used = set().union(*[e.free_symbols for _, e in statements], *[e.free_symbols for e in reduced])
    varying = {s for _, syms in kernel.inputs for s in syms}
    printer = _Printer(varying)
    lanes = kernel.lanes
    at = (lambda k: f'[{k}]') if lanes == 1 else (lambda k: f'[{k} * {lanes} + lane]')
    args = ([f'const {params_type} *p'] + [f'const stewart_vd *{name}' for name, _ in kernel.inputs]
            + [f'stewart_vd *{name}' for name, _ in kernel.outputs])
    signature = f'void vkernel_{kernel.name}({", ".join(args)})'
    lines = [f'/* {kernel.doc} */', signature, '{']
    lines += [f'    const double {s.name} = p->{member};' for s, member in param_members if s in used]
    if not any(s in used for s, _ in param_members):
        lines.append('    (void)p;')
    # an input a variant does not read (the C example's -Werror builds see unused parameters)
    lines += [f'    (void){name};' for name, syms in kernel.inputs if not any(s in used for s in syms)]
    indent = '    '
    if lanes > 1:
        sums = [(name, len(exprs)) for name, exprs in kernel.outputs if name in kernel.sums]
        if sums:  # the sums start at zero
            lines.append('    int k;')
        for name, n in sums:
            lines += [f'    for (k = 0; k < {n}; ++k) {{', f'        {name}[k] = vsplat(0.0);', '    }']
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
            if name in kernel.sums:
                lines.append(f'{indent}{name}[{j}] += {value};')
            else:
                lines.append(f'{indent}{name}{at(j)} = {value if e.free_symbols & varying else f"vsplat({value})"};')
            k += 1
    if lanes > 1:
        lines.append('    }')
    lines.append('}')
    return EmittedKernel(kernel.name, '\n'.join(lines) + '\n', ops, signature)
