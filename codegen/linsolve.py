"""Straight-line C for the two 6x6 linear solves of the public functions, each split into
a factorization and a solve for any number of right-hand sides, so the derivative
functions reuse the factorization of the primal solve.

Both factorizations are fully unrolled into scalar code (no loops), which lets the
compiler keep the matrix in registers and overlap the eliminations; the solves unroll
the six rows and loop over the right-hand sides:

* `bareiss_factor` / `bareiss_solve`: J^T y = b for the leg Jacobian J (inverse
  dynamics), by fraction-free (Bareiss) Gaussian elimination with partial pivoting.
  The pivot row is brought into place by a tournament of conditional row swaps;
  the division by the previous pivot is a multiplication by its reciprocal,
  computed one step early, so no division lies on the elimination's critical
  path.  The last Bareiss pivot is det(J^T) (up to sign), which gives the
  Hadamard-ratio singularity test without a separate pass.  The factors record the
  swaps, the multipliers of every step and the final upper triangle.
* `ldl_factor` / `ldl_solve`: S y = b for the symmetric twist-space mass matrix
  (forward dynamics), by an LDL^T factorization; its pivots d_k are the
  squares of the Cholesky diagonal, so the MASS_SINGULAR test is unchanged
  and no square root is needed.

A solve takes b as 6 rows of n columns with row stride ld (ld >= n) and writes y as 6
rows of n columns with the same row stride; every column is solved with exactly the
operations of a single right-hand side, all of its entries read before any is written, so
y may be b (a solve in place).

Each function also has a vector variant (`vector=True`: `vbareiss_factor`, ...) over a
block of states, one per lane of a `stewart_vd` (codegen/templates/vector.c): the same
operations lane-wise, the conditional row swaps as lane-wise selects, and the status of
each lane returned as a `stewart_vl` (0: STEWART_OK).
"""

from dataclasses import dataclass

N = 6


@dataclass(frozen=True)
class _Types:
    """The C types and names of the scalar or the vector variant of the solvers."""
    real: str     # a number
    flag: str     # a comparison's result
    status: str   # the return type
    prefix: str   # of the function names
    abs: str      # |a|


SCALAR = _Types('double', 'int', 'int', '', 'fabs')
VECTOR = _Types('stewart_vd', 'stewart_vl', 'stewart_vl', 'v', 'vabs')


def _types(vector):
    return VECTOR if vector else SCALAR


def _tournament(rows):
    """Pairs (i, j) of row positions, in order, whose conditional swaps (swap
    when |a_jk| > |a_ik|) leave the largest candidate at rows[0]."""
    pairs, current = [], list(rows)
    while len(current) > 1:
        winners = []
        for a in range(0, len(current) - 1, 2):
            pairs.append((current[a], current[a + 1]))
            winners.append(current[a])
        if len(current) % 2:
            winners.append(current[-1])
        current = winners
    return pairs


class _BareissLayout:
    """Offsets into the factor array of `bareiss_factor`: the swap flags (1.0 or 0.0) of
    the tournaments in order, per step k the pivot a_kk and the entries a_ik (i > k) it
    eliminates, the reciprocal pivots, the final strict upper triangle a_ij (i < j)."""

    def __init__(self):
        self.swaps = [pair for k in range(N) for pair in ((k, p) for p in _tournament(range(k, N)))]
        n = len(self.swaps)
        self.pivot = {k: n + k for k in range(N)}
        n += N
        self.lower, self.upper = {}, {}
        for k in range(N - 1):
            for i in range(k + 1, N):
                self.lower[i, k] = n
                n += 1
        self.inv = {k: n + k for k in range(N)}
        n += N
        for i in range(N):
            for j in range(i + 1, N):
                self.upper[i, j] = n
                n += 1
        self.size = n


BAREISS = _BareissLayout()


def bareiss_factor(vector=False):
    """C text of `static int bareiss_factor(J, F)` (or its vector variant)."""
    L, T = BAREISS, _types(vector)
    lines = ['/* bareiss_factor over a block of states: the swaps lane-wise, F[swap] a lane mask. */',
             f'static stewart_vl vbareiss_factor(const stewart_vd J[36], stewart_vd F[{L.size}])', '{'] if vector else [
        '/* Factor J^T (J 6x6 row-major) by fraction-free (Bareiss) Gaussian elimination',
        ' * with partial pivoting, unrolled; a_rc = (J^T)_rc.  At step k the row of largest',
        ' * |a_ik| (i >= k) is swapped into row k and a_ij <- (a_kk a_ij - a_ik a_kj) /',
        ' * (previous pivot), which keeps every entry a minor of J^T and makes the last pivot',
        ' * a_55 = +-det J.  F receives what bareiss_solve replays (see codegen/linsolve.py).',
        ' * Returns STEWART_ERR_JACOBIAN_SINGULAR when the Hadamard ratio',
        ' * |det J| / prod_i |row_i(J)| < STEWART_JACOBIAN_TOL, else STEWART_OK. */',
        f'static int bareiss_factor(const double J[36], double F[{L.size}])',
        '{',
    ]
    add = lines.append
    for r in range(N):
        add(f'    {T.real} ' + ', '.join(f'a{r}{c} = J[{N * c + r}]' for c in range(N)) + ';')
    for i in range(N):
        add(f'    const {T.real} n{i} = '
            + ' + '.join(f'J[{N * i + j}] * J[{N * i + j}]' for j in range(N)) + ';')
    add(f'    {T.real} t;')
    add(f'    {T.flag} s;')
    swap = 0
    for k in range(N):
        add(f'    /* step {k} */')
        for i, j in _tournament(range(k, N)):
            add(f'    s = {T.abs}(a{j}{k}) > {T.abs}(a{i}{k});')
            add(f'    F[{swap}] = {"(stewart_vd)" if vector else ""}s;')
            swap += 1
            for c in range(k, N):
                add(f'    t = a{i}{c}; ' + _swap(vector, 's', f'a{i}{c}', f'a{j}{c}'))
        add(f'    const {T.real} inv{k} = 1.0 / a{k}{k};')
        add(f'    F[{L.pivot[k]}] = a{k}{k};')
        add(f'    F[{L.inv[k]}] = inv{k};')
        if k == N - 1:
            break
        for i in range(k + 1, N):
            add(f'    F[{L.lower[i, k]}] = a{i}{k};')
            for c in range(k + 1, N):
                e = f'a{k}{k} * a{i}{c} - a{i}{k} * a{k}{c}'
                add(f'    a{i}{c} = ' + (e if k == 0 else f'({e}) * inv{k - 1}') + ';')
    for (i, j), n in L.upper.items():
        add(f'    F[{n}] = a{i}{j};')
    norms = ' * '.join(f'n{i}' for i in range(N))
    last = f'a{N - 1}{N - 1}'
    test = f'{last} * {last} >= STEWART_JACOBIAN_TOL * STEWART_JACOBIAN_TOL * ({norms})'
    if vector:
        add(f'    return ~({test}) & STEWART_ERR_JACOBIAN_SINGULAR;')
    else:
        add(f'    if (!({test})) {{')
        add('        return STEWART_ERR_JACOBIAN_SINGULAR;')
        add('    }')
        add('    return STEWART_OK;')
    add('}')
    return '\n'.join(lines) + '\n'


def _swap(vector, flag, a, b):
    """C text exchanging a and b where `flag` holds, t holding a's value."""
    if vector:
        return f'{a} = vselect({flag}, {b}, t); {b} = vselect({flag}, t, {b});'
    return f'{a} = {flag} ? {b} : t; {b} = {flag} ? t : {b};'


def _solve_head(comment, name, size, extra, vector):
    """The C lines of a solve up to its loop over the columns c of b, with b's column c
    loaded into b0 ... b5 (and the declarations `extra`)."""
    T = _types(vector)
    if vector:
        comment = [f'/* {name} over a block of states. */']
    return comment + [
        f'static {T.status} {T.prefix}{name}(const {T.real} F[{size}], int n, int ld, const {T.real} *b, {T.real} *y)',
        '{',
        '    int c;',
        '    for (c = 0; c < n; ++c) {',
        f'        {T.real} ' + ', '.join(f'b{r} = b[{r} * ld + c]' for r in range(N)) + extra + ';',
    ]


def _solved(vector):
    """The C lines ending a solve."""
    return ['    }', '    return vnone();' if vector else '    return STEWART_OK;', '}']


def bareiss_solve(vector=False):
    """C text of `static int bareiss_solve(F, n, ld, b, y)` (or its vector variant)."""
    L = BAREISS
    lines = _solve_head(['/* Solve J^T y = b for n right-hand sides with the factors F of bareiss_factor: the',
                         ' * same swaps and eliminations on each column of b, then back substitution. */'],
                        'bareiss_solve', L.size, ', t', vector)
    add = lines.append
    swap = 0
    for k in range(N):
        for i, j in _tournament(range(k, N)):
            if vector:
                add(f'        t = b{i}; ' + _swap(vector, f'(stewart_vl)F[{swap}]', f'b{i}', f'b{j}'))
            else:
                add(f'        if (F[{swap}] != 0.0) {{ t = b{i}; b{i} = b{j}; b{j} = t; }}')
            swap += 1
        if k == N - 1:
            break
        for i in range(k + 1, N):
            e = f'F[{L.pivot[k]}] * b{i} - F[{L.lower[i, k]}] * b{k}'
            add(f'        b{i} = ' + (e if k == 0 else f'({e}) * F[{L.inv[k - 1]}]') + ';')
    for i in range(N - 1, -1, -1):
        terms = ''.join(f' - F[{L.upper[i, j]}] * y[{j} * ld + c]' for j in range(i + 1, N))
        add(f'        y[{i} * ld + c] = (b{i}{terms}) * F[{L.inv[i]}];')
    lines += _solved(vector)
    return '\n'.join(lines) + '\n'


#: Size of the factor array of `ldl_factor`: the multipliers l_ik (i > k), then 1 / d_k.
LDL_SIZE = N * (N - 1) // 2 + N


def _ldl_index(i, k):
    """Index of l_ik (i > k) in the factor array of `ldl_factor`."""
    return sum(N - 1 - m for m in range(k)) + (i - k - 1)


def ldl_factor(vector=False):
    """C text of `static int ldl_factor(upper, F)` (or its vector variant)."""
    T = _types(vector)
    diag = [sum(N - r for r in range(k)) for k in range(N)]  # index of S_kk in upper[]
    inv_at = N * (N - 1) // 2
    lines = ['/* ldl_factor over a block of states, lane by lane. */',
             f'static stewart_vl vldl_factor(const stewart_vd upper[21], stewart_vd F[{LDL_SIZE}])', '{'] if vector else [
        '/* Factor S = L D L^T for symmetric S given by its upper triangle (21 entries,',
        ' * row-major), unrolled (m_ij: the upper triangle being eliminated, l_ik = m_ki / d_k);',
        ' * F receives l_ik (i > k, by columns) and then 1 / d_k.  Returns STEWART_ERR_MASS_SINGULAR',
        ' * when a pivot d_k (the square of the Cholesky diagonal) is <= STEWART_MASS_TOL times',
        ' * its diagonal entry S_kk (or S_kk <= 0), else STEWART_OK. */',
        f'static int ldl_factor(const double upper[21], double F[{LDL_SIZE}])',
        '{',
    ]
    add = lines.append
    n = 0
    for i in range(N):
        decl = []
        for j in range(i, N):
            decl.append(f'm{i}{j} = upper[{n}]')
            n += 1
        add(f'    {T.real} ' + ', '.join(decl) + ';')
    add('    stewart_vl ok = ~vnone();' if vector else '    int ok = 1;')
    for k in range(N):
        add(f'    ok &= (upper[{diag[k]}] > 0.0) & (m{k}{k} > STEWART_MASS_TOL * upper[{diag[k]}]);')
        add(f'    const {T.real} inv{k} = 1.0 / m{k}{k};')
        add(f'    F[{inv_at + k}] = inv{k};')
        for i in range(k + 1, N):
            add(f'    const {T.real} l{i}{k} = m{k}{i} * inv{k};')
            add(f'    F[{_ldl_index(i, k)}] = l{i}{k};')
        for i in range(k + 1, N):
            for j in range(i, N):
                add(f'    m{i}{j} -= l{i}{k} * m{k}{j};')
    if vector:
        add('    return ~ok & STEWART_ERR_MASS_SINGULAR;')
    else:
        add('    if (!ok) {')
        add('        return STEWART_ERR_MASS_SINGULAR;')
        add('    }')
        add('    return STEWART_OK;')
    add('}')
    return '\n'.join(lines) + '\n'


def ldl_solve(vector=False):
    """C text of `static int ldl_solve(F, n, ld, b, y)` (or its vector variant)."""
    inv_at = N * (N - 1) // 2
    lines = _solve_head(['/* Solve S y = b for n right-hand sides with the factors F of ldl_factor. */'],
                        'ldl_solve', LDL_SIZE, '', vector)
    add = lines.append
    for k in range(N):
        for i in range(k + 1, N):
            add(f'        b{i} -= F[{_ldl_index(i, k)}] * b{k};')
    for i in range(N - 1, -1, -1):
        terms = ''.join(f' - F[{_ldl_index(j, i)}] * y[{j} * ld + c]' for j in range(i + 1, N))
        add(f'        y[{i} * ld + c] = b{i} * F[{inv_at + i}]{terms};')
    lines += _solved(vector)
    return '\n'.join(lines) + '\n'


def source(vector=False):
    """C text of the four functions (or of their vector variants)."""
    return '\n'.join([bareiss_factor(vector), bareiss_solve(vector), ldl_factor(vector), ldl_solve(vector)])
