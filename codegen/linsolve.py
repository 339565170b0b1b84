"""Straight-line C for the two 6x6 linear solves of the public functions.

Both solvers are fully unrolled into scalar code (no loops, no arrays), which
lets the compiler keep the matrix in registers and overlap the eliminations:

* `solve_transposed`: J^T y = b for the leg Jacobian J (inverse dynamics), by
  fraction-free (Bareiss) Gaussian elimination with partial pivoting.  The
  pivot row is brought into place by a tournament of conditional row swaps;
  the division by the previous pivot is a multiplication by its reciprocal,
  computed one step early, so no division lies on the elimination's critical
  path.  The last Bareiss pivot is det(J^T) (up to sign), which gives the
  Hadamard-ratio singularity test without a separate pass.
* `cholesky_solve`: S y = b for the symmetric twist-space mass matrix
  (forward dynamics), by an LDL^T factorization; its pivots d_k are the
  squares of the Cholesky diagonal, so the MASS_SINGULAR test is unchanged
  and no square root is needed.
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


def solve_transposed():
    """C text of `static int solve_transposed(J, b, y)`."""
    lines = [
        '/* Solve J^T y = b (J 6x6 row-major) by fraction-free (Bareiss) Gaussian',
        ' * elimination with partial pivoting, unrolled; a_rc = (J^T)_rc, column 6 = b.',
        ' * At step k the row of largest |a_ik| (i >= k) is swapped into row k and',
        ' * a_ij <- (a_kk a_ij - a_ik a_kj) / (previous pivot), which keeps every entry',
        ' * a minor of J^T and makes the last pivot a_55 = +-det J.  Returns',
        ' * STEWART_ERR_JACOBIAN_SINGULAR when the Hadamard ratio',
        ' * |det J| / prod_i |row_i(J)| < STEWART_JACOBIAN_TOL, else STEWART_OK. */',
        'static int solve_transposed(const double J[36], const double b[6], double y[6])',
        '{',
    ]
    add = lines.append
    for r in range(N):
        add('    double ' + ', '.join(f'a{r}{c} = J[{N * c + r}]' for c in range(N))
            + f', a{r}6 = b[{r}];')
    for i in range(N):
        add(f'    const double n{i} = '
            + ' + '.join(f'J[{N * i + j}] * J[{N * i + j}]' for j in range(N)) + ';')
    add('    double t;')
    add('    int s;')
    for k in range(N):
        add(f'    /* step {k} */')
        for i, j in _tournament(range(k, N)):
            add(f'    s = fabs(a{j}{k}) > fabs(a{i}{k});')
            for c in range(k, N + 1):
                add(f'    t = a{i}{c}; a{i}{c} = s ? a{j}{c} : t; a{j}{c} = s ? t : a{j}{c};')
        add(f'    const double inv{k} = 1.0 / a{k}{k};')
        if k == N - 1:
            break
        for i in range(k + 1, N):
            for c in range(k + 1, N + 1):
                e = f'a{k}{k} * a{i}{c} - a{i}{k} * a{k}{c}'
                add(f'    a{i}{c} = ' + (e if k == 0 else f'({e}) * inv{k - 1}') + ';')
    norms = ' * '.join(f'n{i}' for i in range(N))
    last = f'a{N - 1}{N - 1}'
    add(f'    if (!({last} * {last} >= STEWART_JACOBIAN_TOL * STEWART_JACOBIAN_TOL * ({norms}))) {{')
    add('        return STEWART_ERR_JACOBIAN_SINGULAR;')
    add('    }')
    for i in range(N - 1, -1, -1):
        terms = ''.join(f' - a{i}{j} * y[{j}]' for j in range(i + 1, N))
        add(f'    y[{i}] = (a{i}6{terms}) * inv{i};')
    add('    return STEWART_OK;')
    add('}')
    return '\n'.join(lines) + '\n'


def cholesky_solve():
    """C text of `static int cholesky_solve(upper, b, y)`."""
    diag = [sum(N - r for r in range(k)) for k in range(N)]  # index of S_kk in upper[]
    lines = [
        '/* Solve S y = b for symmetric S given by its upper triangle (21 entries,',
        ' * row-major) by an unrolled LDL^T factorization (m_ij: the upper triangle',
        ' * being eliminated, l_ik = m_ki / d_k).  Returns STEWART_ERR_MASS_SINGULAR when',
        ' * a pivot d_k (the square of the Cholesky diagonal) is <= STEWART_MASS_TOL times',
        ' * its diagonal entry S_kk (or S_kk <= 0), else STEWART_OK. */',
        'static int cholesky_solve(const double upper[21], const double b[6], double y[6])',
        '{',
    ]
    add = lines.append
    n = 0
    for i in range(N):
        decl = []
        for j in range(i, N):
            decl.append(f'm{i}{j} = upper[{n}]')
            n += 1
        add('    double ' + ', '.join(decl) + ';')
    add('    double ' + ', '.join(f'b{i} = b[{i}]' for i in range(N)) + ';')
    add('    int ok = 1;')
    for k in range(N):
        add(f'    ok &= (upper[{diag[k]}] > 0.0) & (m{k}{k} > STEWART_MASS_TOL * upper[{diag[k]}]);')
        add(f'    const double inv{k} = 1.0 / m{k}{k};')
        for i in range(k + 1, N):
            add(f'    const double l{i}{k} = m{k}{i} * inv{k};')
        for i in range(k + 1, N):
            for j in range(i, N):
                add(f'    m{i}{j} -= l{i}{k} * m{k}{j};')
            add(f'    b{i} -= l{i}{k} * b{k};')
    add('    if (!ok) {')
    add('        return STEWART_ERR_MASS_SINGULAR;')
    add('    }')
    for i in range(N - 1, -1, -1):
        terms = ''.join(f' - l{j}{i} * y[{j}]' for j in range(i + 1, N))
        add(f'    y[{i}] = b{i} * inv{i}{terms};')
    add('    return STEWART_OK;')
    add('}')
    return '\n'.join(lines) + '\n'
