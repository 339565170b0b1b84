"""The derivation's machinery: ordered definitions of named symbols with symbolic forward-mode
derivatives on them (`Graph`, `Tangent`), the 3-vector helpers, and `KernelSpec`, the
straight-line C function a derivation yields and `emit` prints.

Performance rests on two rules, which every derivation in codegen/ follows:

* every intermediate quantity (rotation matrix entries, leg vectors, unit
  vectors, velocities, momenta, ...) gets its own symbol through `Graph.define`,
  so no expression is ever expanded;
* time derivatives, and the partials of the derivative functions, are taken by
  the chain rule on those definitions (`Tangent`, symbolic forward mode along a
  seed: `Graph.rate` along time, `Graph.partials` along inputs), never on
  expanded expressions and never by finite differences.
"""

from dataclasses import dataclass

import sympy as sp


AXES = 'xyz'


def symbols(prefix, n):
    """n real symbols prefix_0, prefix_1, ..."""
    return [sp.Symbol(f'{prefix}_{k}', real=True) for k in range(n)]


def dot(a, b):
    """a . b of 3-vectors."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def skew(a):
    """[a]x: skew(a) * b == a x b."""
    return sp.Matrix([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])


def cross(a, b):
    """a x b of 3-vectors, as a column."""
    return sp.Matrix([a[1] * b[2] - a[2] * b[1],
                      a[2] * b[0] - a[0] * b[2],
                      a[0] * b[1] - a[1] * b[0]])


class Tangent:
    """Symbolic forward-mode derivative of a graph's expressions along one direction.

    `seed` maps independent inputs to their derivatives along the direction (x -> xd for
    the time derivative, x_k -> 1 for the partial along x_k); every other symbol the
    graph does not define is constant.  The derivative of each defined symbol is taken by
    the chain rule on its definition, defined in the graph as `<symbol>_<tag>` (zeros
    are not defined), and cached, so no expression is ever expanded.
    """

    def __init__(self, graph, seed, tag):
        self.graph = graph
        self.seed = dict(seed)
        self.tag = tag
        self._cache = {}

    def __call__(self, expr):
        """Derivative of `expr` along the direction."""
        expr = sp.sympify(expr)
        if expr.is_Symbol:
            return self._symbol(expr)
        if expr.is_Number:
            return sp.S.Zero
        if expr.is_Add:
            return sp.Add(*[d for d in map(self, expr.args) if d is not sp.S.Zero])
        if expr.is_Mul:
            args = expr.args
            terms = [(k, self(a)) for k, a in enumerate(args)]
            return sp.Add(*[sp.Mul(*args[:k], d, *args[k + 1:]) for k, d in terms if d is not sp.S.Zero])
        if expr.is_Pow and expr.exp.is_Number:
            d = self(expr.base)
            return sp.S.Zero if d is sp.S.Zero else expr.exp * expr.base ** (expr.exp - 1) * d
        known = self.graph.known
        if isinstance(expr, (sp.sin, sp.cos)):
            d = self(expr.args[0])
            if d is sp.S.Zero:
                return d
            if isinstance(expr, sp.sin):
                return known(sp.cos(expr.args[0])) * d
            return -known(sp.sin(expr.args[0])) * d
        raise TypeError(f'no derivative rule for {expr.func}')

    def _symbol(self, s):
        if s in self.seed:
            return self.seed[s]
        definition = self.graph.definition(s)
        if definition is None:
            return sp.S.Zero
        if s not in self._cache:
            if definition.is_Pow and definition.exp.is_Number:
                # d(b^k) = k b^k b^-1 db reuses s = b^k (no second root)
                d = self(definition.base)
                d = d if d is sp.S.Zero else definition.exp * s / definition.base * d
            else:
                d = self(definition)
            self._cache[s] = self.graph.define(f'{s.name}_{self.tag}', d)
        return self._cache[s]


class Graph:
    """Ordered symbol definitions with symbolic forward-mode derivatives (`Tangent`).

    `rates` maps the independent inputs to their time derivatives (x -> xd,
    optionally xd -> xdd); every other free symbol is a constant parameter.
    Identical expressions are defined once.
    """

    def __init__(self, rates):
        self.rates = dict(rates)
        self.defs = []
        self._expr = {}
        self._by_expr = {}
        self.rate = Tangent(self, self.rates, 'd')
        """Total time derivative of an expression (forward mode along the rates)."""

    def define(self, name, expr):
        """Name `expr` (returned as is when it is already a number or symbol)."""
        expr = sp.sympify(expr)
        if expr.is_Atom:
            return expr
        if expr in self._by_expr:
            return self._by_expr[expr]
        sym = sp.Symbol(name, real=True)
        if sym in self._expr:
            raise ValueError(f'symbol {name} defined twice')
        self._expr[sym] = expr
        self._by_expr[expr] = sym
        self.defs.append((sym, expr))
        return sym

    def definition(self, sym):
        """The expression `sym` was defined as, or None for an input or parameter."""
        return self._expr.get(sym)

    def known(self, expr):
        """The symbol defined as `expr`, or `expr` itself."""
        return self._by_expr.get(expr, expr)

    def vector(self, name, exprs):
        return sp.Matrix([self.define(f'{name}_{c}', e) for c, e in zip(AXES, exprs)])

    def partials(self, exprs, inputs, tag):
        """Rows d exprs_i / d inputs_j (lists), one `Tangent` per input."""
        columns = [[Tangent(self, {s: sp.S.One}, f'{tag}{j}')(e) for e in exprs]
                   for j, s in enumerate(inputs)]
        return [list(row) for row in zip(*columns)]


@dataclass
class KernelSpec:
    """One straight-line C function: named input arrays -> named output arrays.  With
    `lanes` > 1 it runs on that many independent sets of inputs at once (a loop the
    compiler vectorizes), entry k of set i at index k * lanes + i of every array, but for the
    `shared` inputs, which every lane reads whole, and the `sums` outputs, entry k the sum
    over the lanes, added in lane order."""
    name: str
    doc: str
    graph: Graph
    inputs: list     # [(C array name, [symbols])]
    outputs: list    # [(C array name, [expressions])]
    lanes: int = 1
    shared: tuple = ()  # with lanes > 1: the inputs every lane reads whole
    when: str = None    # of a kernel with variants: the C test under which it runs (None: otherwise)
    sums: tuple = ()    # with lanes > 1: the outputs summed over the lanes

    def size(self, name, exprs):
        """The number of entries of output `name` (its expressions `exprs`): one per lane each
        but for a sum over the lanes."""
        return len(exprs) * (1 if name in self.sums else self.lanes)
