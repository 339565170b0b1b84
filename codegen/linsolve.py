"""Straight-line C for the two 6x6 linear solves of the public functions, each split into
a factorization and a solve for any number of right-hand sides, so the derivative
functions reuse the factorization of the primal solve.

Each works on a block of states, one per lane of a `stewart_vd` (codegen/templates/vector.c):
the same operations on every lane, the conditional row swaps as lane-wise selects, and the
status of each lane returned as a `stewart_vl` (0: STEWART_OK).  Both factorizations are
fully unrolled (no loops), which lets the compiler keep the matrix in registers and overlap
the eliminations; the solves unroll the six rows and loop over the right-hand sides:

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
"""

N = 6


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


def bareiss_factor():
    """C text of `static stewart_vl vbareiss_factor(J, F)`."""
    L = BAREISS
    lines = [
        '/* Factor J^T (J 6x6 row-major) by fraction-free (Bareiss) Gaussian elimination',
        ' * with partial pivoting, unrolled; a_rc = (J^T)_rc.  At step k the row of largest',
        ' * |a_ik| (i >= k) is swapped into row k and a_ij <- (a_kk a_ij - a_ik a_kj) /',
        ' * (previous pivot), which keeps every entry a minor of J^T and makes the last pivot',
        ' * a_55 = +-det J.  F receives what vbareiss_solve replays (see codegen/linsolve.py);',
        ' * the swaps are lane-wise, F[swap] a lane mask.  A lane\'s status is',
        ' * STEWART_ERR_JACOBIAN_SINGULAR when the Hadamard ratio',
        ' * |det J| / prod_i |row_i(J)| < STEWART_JACOBIAN_TOL, else STEWART_OK. */',
        f'static stewart_vl vbareiss_factor(const stewart_vd J[36], stewart_vd F[{L.size}])',
        '{',
    ]
    add = lines.append
    for r in range(N):
        add('    stewart_vd ' + ', '.join(f'a{r}{c} = J[{N * c + r}]' for c in range(N)) + ';')
    for i in range(N):
        add(f'    const stewart_vd n{i} = '
            + ' + '.join(f'J[{N * i + j}] * J[{N * i + j}]' for j in range(N)) + ';')
    add('    stewart_vd t;')
    add('    stewart_vl s;')
    swap = 0
    for k in range(N):
        add(f'    /* step {k} */')
        for i, j in _tournament(range(k, N)):
            add(f'    s = vabs(a{j}{k}) > vabs(a{i}{k});')
            add(f'    F[{swap}] = (stewart_vd)s;')
            swap += 1
            for c in range(k, N):
                add(f'    t = a{i}{c}; ' + _swap('s', f'a{i}{c}', f'a{j}{c}'))
        add(f'    const stewart_vd inv{k} = 1.0 / a{k}{k};')
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
    add(f'    return ~({test}) & STEWART_ERR_JACOBIAN_SINGULAR;')
    add('}')
    return '\n'.join(lines) + '\n'


def _swap(flag, a, b, t='t'):
    """C text exchanging a and b in the lanes where `flag` holds, `t` holding a's value."""
    return f'{a} = vselect({flag}, {b}, {t}); {b} = vselect({flag}, {t}, {b});'


#: The right-hand sides a solve takes at a time, each with the same operations as alone: the
#: columns' chains of dependent operations (the eliminations, the back substitution) overlap.
COLUMNS = 3


def _solve(comment, name, size, column):
    """C text of the solve `v<name>(F, n, ld, b, y)` for n right-hand sides, COLUMNS at a time
    (then one at a time): `column(s, at)` gives the C lines of one column, its variables
    suffixed `s`, at the column index `at`; the columns' lines interleave."""
    def group(width, indent):
        parts = [column(f'_{j}', f'c + {j}' if j else 'c') for j in range(width)]
        return [indent + line for lines in zip(*parts) for line in lines]
    return '\n'.join(comment + [
        f'static stewart_vl v{name}(const stewart_vd F[{size}], int n, int ld, const stewart_vd *b, stewart_vd *y)',
        '{',
        '    int c = 0;',
        f'    for (; c + {COLUMNS} <= n; c += {COLUMNS}) {{', *group(COLUMNS, '        '), '    }',
        '    for (; c < n; ++c) {', *group(1, '        '), '    }',
        '    return vnone();',
        '}']) + '\n'


def _loaded(s, at):
    """The C line loading column `at` of b into b0 ... b5 (suffixed `s`)."""
    return 'stewart_vd ' + ', '.join(f'b{r}{s} = b[{r} * ld + {at}]' for r in range(N)) + ';'


def _stored(s, at):
    """The C lines storing a column's solution y0 ... y5 (suffixed `s`) into column `at` of y:
    every entry of b is read before y is written (y may be b)."""
    return [f'y[{i} * ld + {at}] = y{i}{s};' for i in range(N)]


def bareiss_solve():
    """C text of `static stewart_vl vbareiss_solve(F, n, ld, b, y)`."""
    L = BAREISS

    def column(s, at):
        lines = [_loaded(s, at), f'stewart_vd t{s};']
        swap = 0
        for k in range(N):
            for i, j in _tournament(range(k, N)):
                lines.append(f't{s} = b{i}{s}; ' + _swap(f'(stewart_vl)F[{swap}]', f'b{i}{s}', f'b{j}{s}', f't{s}'))
                swap += 1
            if k == N - 1:
                break
            for i in range(k + 1, N):
                e = f'F[{L.pivot[k]}] * b{i}{s} - F[{L.lower[i, k]}] * b{k}{s}'
                lines.append(f'b{i}{s} = ' + (e if k == 0 else f'({e}) * F[{L.inv[k - 1]}]') + ';')
        for i in range(N - 1, -1, -1):
            terms = ''.join(f' - F[{L.upper[i, j]}] * y{j}{s}' for j in range(i + 1, N))
            lines.append(f'const stewart_vd y{i}{s} = (b{i}{s}{terms}) * F[{L.inv[i]}];')
        return lines + _stored(s, at)

    return _solve(['/* Solve J^T y = b for n right-hand sides with the factors F of vbareiss_factor: the',
                   ' * same swaps and eliminations on each column of b, then back substitution. */'],
                  'bareiss_solve', L.size, column)


#: Size of the factor array of `ldl_factor`: the multipliers l_ik (i > k), then 1 / d_k.
LDL_SIZE = N * (N - 1) // 2 + N


def _ldl_index(i, k):
    """Index of l_ik (i > k) in the factor array of `ldl_factor`."""
    return sum(N - 1 - m for m in range(k)) + (i - k - 1)


def ldl_factor():
    """C text of `static stewart_vl vldl_factor(S, F)`."""
    inv_at = N * (N - 1) // 2
    lines = [
        '/* Factor S = L D L^T for symmetric S (6 x 6, row-major; only its upper triangle is',
        ' * read), unrolled (m_ij: the upper triangle being eliminated, l_ik = m_ki / d_k);',
        ' * F receives l_ik (i > k, by columns) and then 1 / d_k.  A lane\'s status is',
        ' * STEWART_ERR_MASS_SINGULAR when a pivot d_k (the square of the Cholesky diagonal) is',
        ' * <= STEWART_MASS_TOL times its diagonal entry S_kk (or S_kk <= 0), else STEWART_OK. */',
        f'static stewart_vl vldl_factor(const stewart_vd S[{N * N}], stewart_vd F[{LDL_SIZE}])',
        '{',
    ]
    add = lines.append
    for i in range(N):
        add('    stewart_vd ' + ', '.join(f'm{i}{j} = S[{N * i + j}]' for j in range(i, N)) + ';')
    add('    stewart_vl ok = ~vnone();')
    for k in range(N):
        add(f'    ok &= (S[{(N + 1) * k}] > 0.0) & (m{k}{k} > STEWART_MASS_TOL * S[{(N + 1) * k}]);')
        add(f'    const stewart_vd inv{k} = 1.0 / m{k}{k};')
        add(f'    F[{inv_at + k}] = inv{k};')
        for i in range(k + 1, N):
            add(f'    const stewart_vd l{i}{k} = m{k}{i} * inv{k};')
            add(f'    F[{_ldl_index(i, k)}] = l{i}{k};')
        for i in range(k + 1, N):
            for j in range(i, N):
                add(f'    m{i}{j} -= l{i}{k} * m{k}{j};')
    add('    return ~ok & STEWART_ERR_MASS_SINGULAR;')
    add('}')
    return '\n'.join(lines) + '\n'


def ldl_solve():
    """C text of `static stewart_vl vldl_solve(F, n, ld, b, y)`."""
    inv_at = N * (N - 1) // 2

    def column(s, at):
        lines = [_loaded(s, at)]
        for k in range(N):
            for i in range(k + 1, N):
                lines.append(f'b{i}{s} -= F[{_ldl_index(i, k)}] * b{k}{s};')
        for i in range(N - 1, -1, -1):
            terms = ''.join(f' - F[{_ldl_index(j, i)}] * y{j}{s}' for j in range(i + 1, N))
            lines.append(f'const stewart_vd y{i}{s} = b{i}{s} * F[{inv_at + i}]{terms};')
        return lines + _stored(s, at)

    return _solve(['/* Solve S y = b for n right-hand sides with the factors F of vldl_factor. */'],
                  'ldl_solve', LDL_SIZE, column)


def source():
    """C text of the four functions."""
    return '\n'.join([bareiss_factor(), bareiss_solve(), ldl_factor(), ldl_solve()])
