# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""Thin Cython layer over the generated C model (generated/stewart_model.c).

It only moves arrays: it takes one state ``(6,)`` or a batch ``(N, 6)`` (a single row
broadcasts against a batch), makes every input C-contiguous float64 (copying only when
needed), checks that inputs are finite, runs the C function over the rows with the GIL
released (split over threads in blocks of rows when asked: OpenMP threads, or plain threads
in a build without OpenMP), and turns the C status codes into Python errors. A batch goes
through the C batch function (``batch_<name>``, ``LANES`` states per vector instruction), a
single state through the single-state one (the batch function on one row). All the
mathematics is in the generated C.

Two loops that call the model without Python per state are part of the module (included
from their own files, so that the extension compiles Cython's support code once): the
simulator's closed loop (stewart/_simulate.pxi: ``ClosedLoop``) and the envelope's running
peaks (stewart/_envelope.pxi: ``Peaks``, ``box_states``).

The C functions are called through a table (generated/stewart_dispatch.h): the build
compiles the model once per instruction set, and the import picks the copy this CPU runs
best, or the one ``STEWART_SIMD`` names.
"""

import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np

cimport cython
cimport numpy as cnp
from cython.parallel cimport prange
from libc.math cimport isfinite, NAN

from .model import arguments
from .model.errors import SimdPathError, SingularityError

cnp.import_array()


cdef extern from "stewart_dispatch.h" nogil:
    const stewart_table **stewart_tables  # the compiled copies of the model, NULL-terminated
    int stewart_cpu_supports(const char *level)
    const int STEWART_OPENMP


#: The environment variable that forces a compiled copy of the model (a name of
#: ``build_info()["compiled"]``).
SIMD_VARIABLE = "STEWART_SIMD"


cdef list _compiled():
    """(name, level, flags, compiler, whether this CPU runs it) of every compiled copy of the
    model, the one that runs everywhere first."""
    cdef int i = 0
    cdef const stewart_table *t
    out = []
    while stewart_tables[i] != NULL:
        t = stewart_tables[i]
        out.append((t.name.decode(), t.level.decode(), t.flags.decode(), t.compiler.decode(),
                    bool(stewart_cpu_supports(t.level))))
        i += 1
    return out


cdef int _path_index(str name, str source) except -1:
    """The index in stewart_tables of the compiled copy ``name``, or of the last (most capable)
    copy this CPU runs if ``name`` is empty. A name of no path this CPU runs is a ValueError
    naming ``source`` (where the name came from) and the valid values."""
    compiled = _compiled()
    names = [c[0] for c in compiled]
    supported = [c[0] for c in compiled if c[4]]
    if not name:
        return max(i for i, c in enumerate(compiled) if c[4])
    valid = f"valid values: {', '.join(supported)} (or unset: the best this CPU runs)"
    if name not in names:
        raise ValueError(f"{source}={name!r} names no path of this build; {valid}")
    i = names.index(name)
    if not compiled[i][4]:
        raise ValueError(f"{source}={name!r}: this CPU lacks its instruction set ({compiled[i][1]}); {valid}")
    return i


cdef const stewart_table *_choose() except NULL:
    """The table of the copy the kernel runs at import: the one named by STEWART_SIMD, else the
    best this CPU runs. A STEWART_SIMD that names no path this CPU runs is a SimdPathError:
    one line naming the variable and its valid values, exit code 2."""
    try:
        return stewart_tables[_path_index(os.environ.get(SIMD_VARIABLE, ""), SIMD_VARIABLE)]
    except ValueError as exc:
        raise SimdPathError.report(str(exc)) from None


#: The table of functions of the copy of the model in use.
cdef const stewart_table *T = _choose()


def set_simd(path=None):
    """Run the model on the compiled path ``path`` from now on, in this process (a name of
    ``build_info()["supported"]``; ``None``: the best this CPU runs, whatever STEWART_SIMD
    says); returns the name of the path that ran before. The paths give the same results bit
    for bit and differ in speed. Not to be called while another thread runs the model."""
    global T, LANES, C_LANES
    if path is not None and not isinstance(path, str):
        raise TypeError(f"path must be a str or None, not {type(path).__name__}")
    previous = T.name.decode()
    T = stewart_tables[_path_index(path or "", "path")]
    LANES = C_LANES = T.batch_lanes()
    return previous


def build_info():
    """How the kernel was built and what it runs: the path in use (``simd``), the paths
    compiled in and those this CPU supports, each path's compiler and flags, and whether
    batches run on OpenMP threads (else on plain threads)."""
    compiled = _compiled()
    return {
        "simd": T.name.decode(),
        "compiled": [c[0] for c in compiled],
        "supported": [c[0] for c in compiled if c[4]],
        "compiler": T.compiler.decode(),
        "flags": {c[0]: c[2] for c in compiled},
        "openmp": bool(STEWART_OPENMP),
        "threads": "OpenMP" if STEWART_OPENMP else "Python threads over the C loop, without the GIL",
    }


#: (member, shape) of every member of the C struct stewart_params, in order: the fields of a
#: PlatformParams that reach the C model (the generator's parameter schema).
PARAM_FIELDS = stewart_params_fields()
#: {member: the PlatformParams attribute (a field or a property) it is copied from}.
PARAM_SOURCES = stewart_params_sources()
#: The fields of a PlatformParams the members are copied from.
PARAM_INPUTS = stewart_params_inputs()
#: The fields of a PlatformParams with no member in stewart_params, and why.
PARAMS_LEFT_OUT = stewart_params_left_out()


#: {status code: (name, message, tolerance or None)} of every status code of the C model: the
#: conditions under which it is undefined and the tolerances of their tests (read by
#: stewart.model.conditions).
CONDITIONS = stewart_conditions()
#: The inertial parameters pi of the regressor, in the order of its columns.
INERTIAL_NAMES = stewart_inertial_names()


def status_message(int status):
    """The generated C's description of a status code."""
    return T.status_message(status).decode()


ctypedef int (*state_fn)(const stewart_params *, const double *, double *) noexcept nogil
ctypedef int (*rate_fn)(const stewart_params *, const double *, const double *, double *) noexcept nogil
ctypedef int (*dynamics_fn)(const stewart_params *, const double *, const double *, const double *,
                            double *) noexcept nogil
ctypedef int (*four_outputs_fn)(const stewart_params *, const double *, const double *, const double *,
                               double *, double *, double *, double *) noexcept nogil
ctypedef int (*terms_fn)(const stewart_params *, const double *, const double *, double *, double *, double *,
                         double *) noexcept nogil
ctypedef int (*step_fn)(const stewart_params *, const double *, const double *, const double *, double,
                        double *, double *) noexcept nogil
ctypedef int (*step_derivatives_fn)(const stewart_params *, const double *, const double *, const double *,
                                    double, double *, double *, double *, double *) noexcept nogil

ctypedef int (*batch_state_fn)(const stewart_params *, size_t, const double *, double *, int *) noexcept nogil
ctypedef int (*batch_rate_fn)(const stewart_params *, size_t, const double *, const double *, double *,
                              int *) noexcept nogil
ctypedef int (*batch_dynamics_fn)(const stewart_params *, size_t, const double *, const double *,
                                  const double *, double *, int *) noexcept nogil
ctypedef int (*batch_four_outputs_fn)(const stewart_params *, size_t, const double *, const double *,
                                     const double *, double *, double *, double *, double *, int *) noexcept nogil
ctypedef int (*batch_terms_fn)(const stewart_params *, size_t, const double *, const double *, double *, double *,
                               double *, double *, int *) noexcept nogil
ctypedef int (*batch_step_fn)(const stewart_params *, size_t, const double *, const double *, const double *,
                              double, double *, double *, int *) noexcept nogil
ctypedef int (*batch_step_derivatives_fn)(const stewart_params *, size_t, const double *, const double *,
                                          const double *, double, double *, double *, double *, double *,
                                          int *) noexcept nogil

#: Rows of a batch function's states evaluated at once (one per vector lane of the copy in use).
LANES = T.batch_lanes()
cdef Py_ssize_t C_LANES = T.batch_lanes()

cdef enum:
    NONFINITE_INPUT = -1  # status of a row whose input is not finite (C status codes are >= 0)
    MAX_OUTPUTS = 4
    # Bytes of inputs and outputs a thread takes at a time from a batch function: whole blocks
    # of LANES rows, within a core's L1 and L2 caches (Zen 4: 32 kB, 1 MB).
    BATCH_BYTES = 65536

cdef enum Signature:
    # The C signatures _run calls: 1-3 input arrays and one output, or as named.
    FOUR_OUTPUTS = 4      # (p, x0, x1, x2, out0, out1, out2, out3)
    STEP = 5              # (p, x0, x1, x2, scalar, out0, out1)
    STEP_DERIVATIVES = 6  # (p, x0, x1, x2, scalar, out0, out1, out2, out3)
    TERMS = 7             # (p, x0, x1, out0, out1, out2, out3)


cdef cnp.ndarray _states(str name, object value):
    """``value`` as a C-contiguous, aligned, native-byte-order float64 array of shape (6,)
    or (N, 6); no copy if it is one. What is a valid state array is decided in one place,
    :func:`stewart.arguments.state_array`; the fast path only recognises arrays that need
    no conversion (finiteness is checked row by row in ``Kernel._row``)."""
    cdef cnp.ndarray arr
    if type(value) is cnp.ndarray:
        arr = <cnp.ndarray>value
        if ((arr.ndim == 1 or arr.ndim == 2) and arr.shape[arr.ndim - 1] == 6
                and cnp.PyArray_TYPE(arr) == cnp.NPY_DOUBLE and cnp.PyArray_IS_C_CONTIGUOUS(arr)
                and cnp.PyArray_ISBEHAVED_RO(arr)):
            return arr
    return np.require(arguments.state_array(name, value), np.float64, "CA")


cdef cnp.ndarray _c_array(str name, object value, int typenum, int ndim, bint writable):
    """``value`` as it is, an array that C reads (and writes, if ``writable``) through its data
    pointer: an ndarray of the type ``typenum`` with ``ndim`` dimensions, C-contiguous, aligned,
    in native byte order. Anything else is a ValueError naming the argument ``name``."""
    cdef cnp.ndarray arr
    if isinstance(value, cnp.ndarray):
        arr = <cnp.ndarray>value
        if (arr.ndim == ndim and cnp.PyArray_TYPE(arr) == typenum and cnp.PyArray_IS_C_CONTIGUOUS(arr)
                and (cnp.PyArray_ISBEHAVED(arr) if writable else cnp.PyArray_ISBEHAVED_RO(arr))):
            return arr
    raise ValueError(f"{name}: need a {'writable ' if writable else ''}C-contiguous, aligned ndarray of "
                     f"{cnp.PyArray_DescrFromType(typenum)} with {ndim} dimension(s), got {type(value).__name__} "
                     f"{np.shape(value)}")


cdef inline bint _finite6(const double *v) noexcept nogil:
    cdef int k
    for k in range(6):
        if not isfinite(v[k]):
            return False
    return True


cdef object _parts(object result, bint return_mask, tuple shapes):
    """Split the rows of a C function's one output array into its parts of ``shapes``
    (``(6,)`` or ``(6, 6)``; row-major), each C-contiguous; ``result`` is as ``Kernel._run``
    returns."""
    out = result[0] if return_mask else result
    parts, start = [], 0
    for shape in shapes:
        size = 36 if len(shape) == 2 else 6
        part = out[..., start:start + size]
        parts.append(np.ascontiguousarray(part.reshape(part.shape[:-1] + shape)))
        start += size
    return (tuple(parts), result[1]) if return_mask else tuple(parts)


#: Row shapes of the outputs of the C functions.
_VECTOR = ((6,),)
_MATRIX = ((6, 6),)
_DERIVATIVES = ((6,), (6, 6), (6, 6), (6, 6))
_STEP = ((6,), (6,))
_JOINT_REACTIONS = ((6,), (6, 3), (6, 3), (6, 3))
_STEP_DERIVATIVES = ((6,), (6,), (12, 12), (12, 6))
_TERMS = ((6, 6), (6,), (6,), (6, 6))


cdef inline void _batch_call(const stewart_params *p, int kind, void *fn, Py_ssize_t start, Py_ssize_t count,
                             const double *x0, const double *x1, const double *x2, double scalar,
                             int nout, double **outs, const int *widths, int *status) noexcept nogil:
    """Rows start ... start + count - 1 of a batch through the batch function ``fn`` (``kind``
    1-3 inputs and one output, or a ``Signature``), its ``nout`` outputs in ``outs``."""
    cdef double *o[MAX_OUTPUTS]
    cdef int k
    for k in range(nout):
        o[k] = outs[k] + widths[k] * start
    x0 += 6 * start
    x1 += 6 * start
    x2 += 6 * start
    if kind == 1:
        (<batch_state_fn>fn)(p, count, x0, o[0], status + start)
    elif kind == 2:
        (<batch_rate_fn>fn)(p, count, x0, x1, o[0], status + start)
    elif kind == 3:
        (<batch_dynamics_fn>fn)(p, count, x0, x1, x2, o[0], status + start)
    elif kind == FOUR_OUTPUTS:
        (<batch_four_outputs_fn>fn)(p, count, x0, x1, x2, o[0], o[1], o[2], o[3], status + start)
    elif kind == TERMS:
        (<batch_terms_fn>fn)(p, count, x0, x1, o[0], o[1], o[2], o[3], status + start)
    elif kind == STEP:
        (<batch_step_fn>fn)(p, count, x0, x1, x2, scalar, o[0], o[1], status + start)
    else:
        (<batch_step_derivatives_fn>fn)(p, count, x0, x1, x2, scalar, o[0], o[1], o[2], o[3], status + start)


cdef Py_ssize_t _batch_block(int arity, int nout, const int *widths) noexcept nogil:
    """Rows a thread takes at a time from a batch function: BATCH_BYTES of their inputs,
    outputs and statuses, in whole blocks of LANES rows."""
    cdef Py_ssize_t k, row = 6 * arity * sizeof(double) + sizeof(int)
    for k in range(nout):
        row += widths[k] * sizeof(double)
    return max(1, BATCH_BYTES // row // C_LANES) * C_LANES


@cython.final
cdef class Kernel:
    """The compiled model for one parameter set. ``threads`` > 1 splits batches over
    that many threads."""

    def __cinit__(self, params, threads=1):
        stewart_params_fill(&self.p, params)
        self.threads = arguments.thread_count(threads)

    cdef object _run(self, str fname, int kind, void *fn, tuple names, tuple values,
                     tuple shapes, bint return_mask, double scalar, void *batch_fn):
        """Evaluate the single-state function ``fn`` on one state, or its batch function
        ``batch_fn`` on a batch: ``kind`` 1-3 input arrays and one output, or a ``Signature``
        (three inputs, and ``scalar`` the same for every row); an output array per row shape in
        ``shapes``, returned as it is for one, as a tuple for several."""
        cdef cnp.ndarray a0, a1, a2, status
        cdef const double *p0
        cdef const double *p1
        cdef const double *p2
        cdef double *po[MAX_OUTPUTS]
        cdef int widths[MAX_OUTPUTS]
        cdef int *ps
        cdef int status1 = 0
        cdef cnp.npy_intp n = 1
        cdef bint batch = False
        cdef int nthreads = self.threads
        cdef Py_ssize_t block
        cdef int failures = 0
        cdef int k, nout = len(shapes)
        cdef int arity = kind if kind <= 3 else 2 if kind == TERMS else 3
        cdef cnp.npy_intp dims[3]
        cdef int nd

        a0 = _states(names[0], values[0])
        a1 = _states(names[1], values[1]) if arity > 1 else a0
        a2 = _states(names[2], values[2]) if arity > 2 else a0
        if a0.ndim == 2 or a1.ndim == 2 or a2.ndim == 2:
            for arr in (a0, a1, a2):
                if arr.ndim == 2:
                    if batch and arr.shape[0] != n:
                        raise ValueError(
                            "arguments must have matching batch shapes: "
                            + ", ".join(f"{nm} {np.shape(v)}" for nm, v in zip(names, values)))
                    batch, n = True, arr.shape[0]

        outs = []
        for k in range(nout):
            shape = shapes[k]
            nd = 0
            if batch:
                dims[nd] = n
                nd += 1
            widths[k] = 1
            for size in shape:
                dims[nd] = size
                nd += 1
                widths[k] *= size
            out = cnp.PyArray_EMPTY(nd, dims, cnp.NPY_DOUBLE, 0)
            po[k] = <double *>cnp.PyArray_DATA(out)
            outs.append(out)
        if n == 1:  # one row's status needs no array unless it fails
            status = None
            ps = &status1
        else:
            status = cnp.PyArray_ZEROS(1, &n, cnp.NPY_INT, 0)
            ps = <int *>cnp.PyArray_DATA(status)
        p0 = <const double *>cnp.PyArray_DATA(a0)
        p1 = <const double *>cnp.PyArray_DATA(a1)
        p2 = <const double *>cnp.PyArray_DATA(a2)

        if batch:
            # The batch function takes whole arrays: a row broadcast against the batch is copied.
            if a0.ndim == 1: a0 = np.ascontiguousarray(np.broadcast_to(a0, (n, 6)))
            if a1.ndim == 1: a1 = np.ascontiguousarray(np.broadcast_to(a1, (n, 6)))
            if a2.ndim == 1: a2 = np.ascontiguousarray(np.broadcast_to(a2, (n, 6)))
            p0 = <const double *>cnp.PyArray_DATA(a0)
            p1 = <const double *>cnp.PyArray_DATA(a1)
            p2 = <const double *>cnp.PyArray_DATA(a2)
            block = _batch_block(arity, nout, widths)
            if nthreads > 1 and n > block and not STEWART_OPENMP:
                self._threads(kind, batch_fn, scalar, nout, n, block, p0, p1, p2, po, widths, ps)
            else:
                with nogil:
                    self._batch(kind, batch_fn, n, block, p0, p1, p2, scalar, nout, po, widths, ps)
            failures = np.count_nonzero(status) if status is not None else status1 != STEWART_OK
        else:
            failures = self._row(kind, fn, p0, p1, p2, scalar, po, widths, nout, 0, ps)
        result = outs[0] if nout == 1 else tuple(outs)
        if failures == 0:
            return (result, np.ones(n, dtype=bool) if batch else True) if return_mask else result
        if status is None:
            status = np.array([status1], dtype=np.intc)
        return self._failed(fname, names, (a0, a1, a2)[:arity], result, status, batch, return_mask)

    cdef void _batch(self, int kind, void *fn, Py_ssize_t n, Py_ssize_t block, const double *x0,
                     const double *x1, const double *x2, double scalar, int nout, double **outs,
                     const int *widths, int *status) noexcept nogil:
        """The batch function ``fn`` (``kind`` as for ``_batch_call``) on n rows, in blocks of
        ``block`` rows split over OpenMP threads (one thread without OpenMP)."""
        cdef Py_ssize_t b, start, count, nblocks = (n + block - 1) // block
        if self.threads > 1 and nblocks > 1:
            for b in prange(nblocks, num_threads=self.threads, schedule="dynamic"):
                start = b * block
                count = min(block, n - start)
                _batch_call(&self.p, kind, fn, start, count, x0, x1, x2, scalar, nout, outs, widths, status)
        else:
            _batch_call(&self.p, kind, fn, 0, n, x0, x1, x2, scalar, nout, outs, widths, status)

    cdef int _threads(self, int kind, void *fn, double scalar, int nout, Py_ssize_t n, Py_ssize_t block,
                      const double *p0, const double *p1, const double *p2, double **po, const int *widths,
                      int *ps) except -1:
        """The n rows split over plain threads (a build without OpenMP) in blocks of ``block``
        rows, through the batch function ``fn``."""
        blocks = _Blocks(self, kind, <Py_ssize_t>fn, scalar, nout, n, block)
        blocks.p0, blocks.p1, blocks.p2 = p0, p1, p2
        blocks.po, blocks.widths, blocks.ps = po, widths, ps
        with ThreadPoolExecutor(self.threads) as pool:
            list(pool.map(blocks.run, range(self.threads), [self.threads] * self.threads))
        return 0

    cdef int _row(self, int kind, void *fn, const double *x0, const double *x1, const double *x2,
                  double scalar, double **outs, const int *widths, int nout, Py_ssize_t row,
                  int *status) noexcept nogil:
        """Row ``row``: its outputs start ``row * widths[k]`` into ``outs[k]``."""
        cdef int j, k
        cdef double *o[MAX_OUTPUTS]
        for k in range(nout):
            o[k] = outs[k] + row * widths[k]
        if not (_finite6(x0) and (kind < 2 or _finite6(x1)) and (kind < 3 or _finite6(x2))):
            status[0] = NONFINITE_INPUT
            for k in range(nout):
                for j in range(widths[k]):
                    o[k][j] = NAN
            return 1
        if kind == 1:
            status[0] = (<state_fn>fn)(&self.p, x0, o[0])
        elif kind == 2:
            status[0] = (<rate_fn>fn)(&self.p, x0, x1, o[0])
        elif kind == 3:
            status[0] = (<dynamics_fn>fn)(&self.p, x0, x1, x2, o[0])
        elif kind == FOUR_OUTPUTS:
            status[0] = (<four_outputs_fn>fn)(&self.p, x0, x1, x2, o[0], o[1], o[2], o[3])
        elif kind == TERMS:
            status[0] = (<terms_fn>fn)(&self.p, x0, x1, o[0], o[1], o[2], o[3])
        elif kind == STEP:
            status[0] = (<step_fn>fn)(&self.p, x0, x1, x2, scalar, o[0], o[1])
        else:
            status[0] = (<step_derivatives_fn>fn)(&self.p, x0, x1, x2, scalar, o[0], o[1], o[2], o[3])
        return status[0] != STEWART_OK

    cdef object _failed(self, str fname, tuple names, tuple arrays, object out,
                        cnp.ndarray status, bint batch, bint return_mask):
        # The batch functions report a row with a non-finite input as STEWART_ERR_NONFINITE.
        if np.any((status == NONFINITE_INPUT) | (status == STEWART_ERR_NONFINITE)):
            for name, arr in zip(names, arrays):
                arguments.finite_states(name, arr)
        rows = np.flatnonzero(status != STEWART_OK)
        if return_mask:
            return out, (status == STEWART_OK) if batch else bool(status[0] == STEWART_OK)
        condition, message, _ = CONDITIONS[status[rows[0]]]
        raise SingularityError.at_rows(fname, condition, message, rows.tolist(), batch)

    cdef int leg_lengths_c(self, const double *x, double *out) noexcept nogil:
        return T.leg_lengths(&self.p, x, out)

    cdef int leg_rates_c(self, const double *x, const double *xd, double *L, double *Ld) noexcept nogil:
        cdef double out[12]
        cdef int k
        cdef int status = T.leg_rates(&self.p, x, xd, out)
        for k in range(6):
            L[k] = out[k]
            Ld[k] = out[6 + k]
        return status

    cdef int inverse_dynamics_c(self, const double *x, const double *xd, const double *xdd,
                                double *out) noexcept nogil:
        return T.inverse_dynamics(&self.p, x, xd, xdd, out)

    cdef int forward_dynamics_c(self, const double *x, const double *xd, const double *tau,
                                double *out) noexcept nogil:
        return T.forward_dynamics(&self.p, x, xd, tau, out)

    cdef void batch_leg_rates_c(self, size_t n, const double *x, const double *xd, double *LLd,
                                int *status) noexcept nogil:
        T.batch_leg_rates(&self.p, n, x, xd, LLd, status)

    cdef void batch_joint_reactions_c(self, size_t n, const double *x, const double *xd, const double *xdd,
                                      double *tau, double *f_base, double *f_platform, double *n_base,
                                      int *status) noexcept nogil:
        T.batch_joint_reactions(&self.p, n, x, xd, xdd, tau, f_base, f_platform, n_base, status)

    def leg_lengths(self, x, return_mask=False):
        return self._run("leg_lengths", 1, <void *>T.leg_lengths, ("x",), (x,), _VECTOR, return_mask,
                         0.0, <void *>T.batch_leg_lengths)

    def jacobian(self, x, return_mask=False):
        return self._run("jacobian", 1, <void *>T.jacobian, ("x",), (x,), _MATRIX, return_mask,
                         0.0, <void *>T.batch_jacobian)

    def leg_rates(self, x, xd, return_mask=False):
        """``(L, Ldot)`` from the C function's one array ``[L; Ldot]`` per row."""
        return _parts(self._run("leg_rates", 2, <void *>T.leg_rates, ("x", "xd"), (x, xd), ((12,),), return_mask,
                                0.0, <void *>T.batch_leg_rates),
                      return_mask, ((6,), (6,)))

    def all_terms(self, x, xd, return_mask=False):
        """``(M, V xd, G, J_C)``."""
        return self._run("all_terms", TERMS, <void *>T.all_terms, ("x", "xd"), (x, xd), _TERMS, return_mask,
                         0.0, <void *>T.batch_all_terms)

    def mass_matrix(self, x, return_mask=False):
        return self._run("mass_matrix", 1, <void *>T.mass_matrix, ("x",), (x,), _MATRIX, return_mask,
                         0.0, <void *>T.batch_mass_matrix)

    def twist_mass_matrix(self, x, return_mask=False):
        return self._run("twist_mass_matrix", 1, <void *>T.twist_mass_matrix, ("x",), (x,), _MATRIX,
                         return_mask,
                         0.0, <void *>T.batch_twist_mass_matrix)

    def gravity_vector(self, x, return_mask=False):
        return self._run("gravity_vector", 1, <void *>T.gravity_vector, ("x",), (x,), _VECTOR, return_mask,
                         0.0, <void *>T.batch_gravity_vector)

    def coriolis_matrix(self, x, xd, return_mask=False):
        return self._run("coriolis_matrix", 2, <void *>T.coriolis_matrix, ("x", "xd"), (x, xd), _MATRIX,
                         return_mask,
                         0.0, <void *>T.batch_coriolis_matrix)

    def coriolis_vector(self, x, xd, return_mask=False):
        return self._run("coriolis_vector", 2, <void *>T.coriolis_vector, ("x", "xd"), (x, xd), _VECTOR,
                         return_mask,
                         0.0, <void *>T.batch_coriolis_vector)

    def inverse_dynamics(self, x, xd, xdd, return_mask=False):
        return self._run("inverse_dynamics", 3, <void *>T.inverse_dynamics, ("x", "xd", "xdd"),
                         (x, xd, xdd), _VECTOR, return_mask,
                         0.0, <void *>T.batch_inverse_dynamics)

    def forward_dynamics(self, x, xd, tau, return_mask=False):
        return self._run("forward_dynamics", 3, <void *>T.forward_dynamics, ("x", "xd", "tau"),
                         (x, xd, tau), _VECTOR, return_mask,
                         0.0, <void *>T.batch_forward_dynamics)

    def inverse_dynamics_derivatives(self, x, xd, xdd, return_mask=False):
        """``(tau, dtau_dx, dtau_dxd, dtau_dxdd)``."""
        return self._run("inverse_dynamics_derivatives", FOUR_OUTPUTS, <void *>T.inverse_dynamics_derivatives,
                         ("x", "xd", "xdd"), (x, xd, xdd), _DERIVATIVES, return_mask,
                         0.0, <void *>T.batch_inverse_dynamics_derivatives)

    def forward_dynamics_derivatives(self, x, xd, tau, return_mask=False):
        """``(xdd, dxdd_dx, dxdd_dxd, dxdd_dtau)``."""
        return self._run("forward_dynamics_derivatives", FOUR_OUTPUTS, <void *>T.forward_dynamics_derivatives,
                         ("x", "xd", "tau"), (x, xd, tau), _DERIVATIVES, return_mask,
                         0.0, <void *>T.batch_forward_dynamics_derivatives)

    def joint_reactions(self, x, xd, xdd, return_mask=False):
        """``(tau, f_base, f_platform, n_base)``, the last three ``(6, 3)`` per row."""
        return self._run("joint_reactions", FOUR_OUTPUTS, <void *>T.joint_reactions, ("x", "xd", "xdd"),
                         (x, xd, xdd), _JOINT_REACTIONS, return_mask, 0.0, <void *>T.batch_joint_reactions)

    def regressor(self, x, xd, xdd, return_mask=False):
        """Y, ``(6, len(INERTIAL_NAMES))`` per row."""
        return self._run("regressor", 3, <void *>T.regressor, ("x", "xd", "xdd"), (x, xd, xdd),
                         ((6, len(INERTIAL_NAMES)),), return_mask, 0.0, <void *>T.batch_regressor)

    def friction_forces(self, rates, law):
        """The forces the legs lose to friction (the C model's law, stewart_batch_friction_forces)
        at the leg rates ``rates`` (``(6,)`` or ``(N, 6)``, C-contiguous float64) for the law
        ``(F_v (6,), F_c (6,), v_c)``: an array of the shape of ``rates``, NaN in a row whose
        rates or forces are not finite."""
        cdef cnp.ndarray crates = _c_array("rates", rates, cnp.NPY_DOUBLE, np.ndim(rates), False)
        cdef cnp.ndarray out = np.empty_like(crates)
        cdef stewart_friction f = as_friction(law)
        cdef size_t n = crates.size // 6
        with nogil:
            T.batch_friction_forces(&f, n, <const double *>cnp.PyArray_DATA(crates), <double *>cnp.PyArray_DATA(out),
                                    NULL)
        return out

    def rk4_step(self, x, xd, tau, double dt, bint jacobians=False, return_mask=False):
        """``(x, xd)`` after one RK4 step of ``dt`` (a positive finite number, checked by the
        caller), with ``(A, B)`` after them when ``jacobians``."""
        if jacobians:
            return self._run("rk4_step", STEP_DERIVATIVES, <void *>T.rk4_step_derivatives, ("x", "xd", "tau"),
                             (x, xd, tau), _STEP_DERIVATIVES, return_mask, dt, <void *>T.batch_rk4_step_derivatives)
        return self._run("rk4_step", STEP, <void *>T.rk4_step, ("x", "xd", "tau"), (x, xd, tau), _STEP,
                         return_mask, dt, <void *>T.batch_rk4_step)


@cython.final
cdef class _Blocks:
    """A batch split over plain threads (a build without OpenMP): thread ``k`` of ``m`` runs
    blocks k, k + m, ... of ``block`` rows without the GIL, through the batch function."""
    cdef Kernel kernel
    cdef int kind, nout
    cdef void *fn
    cdef double scalar
    cdef Py_ssize_t n, block
    cdef const double *p0
    cdef const double *p1
    cdef const double *p2
    cdef double **po
    cdef const int *widths
    cdef int *ps

    def __cinit__(self, Kernel kernel, int kind, Py_ssize_t fn, double scalar, int nout, Py_ssize_t n,
                  Py_ssize_t block):
        self.kernel, self.kind, self.fn, self.scalar, self.nout, self.n = kernel, kind, <void *>fn, scalar, nout, n
        self.block = block

    def run(self, Py_ssize_t first, Py_ssize_t step):
        """Run blocks ``first``, ``first + step``, ...."""
        cdef Py_ssize_t start
        with nogil:
            start = first * self.block
            while start < self.n:
                _batch_call(&self.kernel.p, self.kind, self.fn, start, min(self.block, self.n - start),
                            self.p0, self.p1, self.p2, self.scalar, self.nout, self.po, self.widths, self.ps)
                start += step * self.block


include "_simulate.pxi"
include "_envelope.pxi"
