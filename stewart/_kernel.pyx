# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""Thin Cython layer over the generated C model (generated/stewart_model.c).

It only moves arrays, the same way for every public function of the C model, as the
generated table stewart._generated.FUNCTIONS describes it (its inputs, its scalar input, its
outputs and the shapes of its results): it takes one state ``(6,)`` or a batch ``(N, 6)`` (a
single row broadcasts against a batch), makes every input C-contiguous float64 (copying only
when needed), runs the C function over the rows with the GIL released (split over threads in
blocks of rows when asked: OpenMP threads, or plain threads in a build without OpenMP), and
turns the C status codes into Python errors (a non-finite input names its argument). Every
function is called through its entry of the table's ``call`` (stewart_dispatch.h): its batch
function (``batch_<name>``, ``LANES`` states per vector instruction), on one row for a single
state. All the mathematics is in the generated C.

The loops that call the model without Python per state are part of the module (included
from their own files, so that the extension compiles Cython's support code once): the
simulator's closed loop (stewart/_simulate.pxi: ``ClosedLoop``), the envelope's running
peaks (stewart/_envelope.pxi: ``Peaks``, ``box_states``), the modes (stewart/_modes.pxi:
``modal_terms``) and an MPC cueing step's QP (stewart/_cueing.pxi and _cueing_rows.pxi:
``CueingStep``).

The C functions are called through a table (generated/stewart_dispatch.h): the build
compiles the model once per instruction set, and the import picks the copy this CPU runs
best, or the one ``STEWART_SIMD`` names.
"""

import math
import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np

cimport cython
cimport numpy as cnp
from cpython.ref cimport Py_INCREF
from cpython.tuple cimport PyTuple_New, PyTuple_SET_ITEM
from cython.parallel cimport prange

from .model import arguments
# The tables of the generated model (parameters, status codes, public functions), read here and
# also importable from here.
from ._generated import (CONDITIONS, FUNCTIONS, INERTIAL_NAMES, PARAM_FIELDS, PARAM_INPUTS, PARAM_SOURCES,
                         PARAMS_LEFT_OUT)
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


#: The fields a parameter set must have: those the members of stewart_params are copied from,
#: and those left out.
cdef frozenset _PARAM_NAMES = frozenset(PARAM_INPUTS).union(PARAMS_LEFT_OUT)


def status_message(int status):
    """The generated C's description of a status code."""
    return T.status_message(status).decode()


#: Rows of a batch function's states evaluated at once (one per vector lane of the copy in use).
LANES = T.batch_lanes()
cdef Py_ssize_t C_LANES = T.batch_lanes()

cdef enum:
    # Bytes of inputs and outputs a thread takes at a time from a batch function: whole blocks
    # of LANES rows, within a core's L1 and L2 caches (Zen 4: 32 kB, 1 MB).
    BATCH_BYTES = 65536
    # The most dimensions of an output array: the batch's and a row's (up to three: the legs'
    # unit vectors' pose gradients, 6 x 3 x 6).
    MAX_DIMS = 4


cdef cnp.ndarray _states(str name, object value):
    """``value`` as a C-contiguous, aligned, native-byte-order float64 array of shape (6,)
    or (N, 6); no copy if it is one. What is a valid state array is decided in one place,
    :func:`stewart.arguments.state_array`; the fast path only recognises arrays that need
    no conversion (finiteness is checked by the C, row by row)."""
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


@cython.final
cdef class _Function:
    """A public function of the C model as the mover calls it: its entry of
    stewart._generated.FUNCTIONS, with the sizes of its arrays at hand for C."""

    def __cinit__(self, str name, spec):
        cdef int k, j
        self.name, self.index, self.inputs, self.results = name, spec.index, tuple(spec.inputs), tuple(spec.results)
        self.nin, self.nout, self.scalar = len(spec.inputs), len(spec.outputs), spec.scalar
        if not 0 <= self.index < STEWART_FUNCTIONS or self.nin > STEWART_MAX_INPUTS or self.nout > STEWART_MAX_OUTPUTS:
            raise ImportError(f"stewart._generated does not match the compiled model ({name}): rebuild")
        # Each result a whole output: the outputs are made in the results' shapes.
        self.whole = len(self.results) == self.nout and all(
            output == k and offset == 0 for k, (_, output, offset, _) in enumerate(self.results))
        self.parts = tuple((output, offset, offset + math.prod(shape), shape)
                           for _, output, offset, shape in self.results)
        for k, (_, width) in enumerate(spec.outputs):
            self.widths[k] = width
            shape = self.results[k][3] if self.whole else (width,)
            self.ndims[k] = len(shape)
            if self.ndims[k] > MAX_DIMS - 1:
                raise ImportError(f"{name}: an output of more than {MAX_DIMS - 1} dimensions per row")
            for j in range(self.ndims[k]):
                self.dims[k][j] = shape[j]

    cdef object split(self, tuple outputs):
        """The results, parts of the rows of the C function's ``outputs``, each C-contiguous."""
        parts = []
        for output, start, stop, shape in self.parts:
            part = outputs[output][..., start:stop]
            parts.append(np.ascontiguousarray(part.reshape(tuple(part.shape)[:part.ndim - 1] + shape)))
        return parts[0] if len(parts) == 1 else tuple(parts)


#: {name: _Function} of every public function of the C model (stewart._generated.FUNCTIONS).
cdef dict _FUNCTIONS = {name: _Function(name, spec) for name, spec in FUNCTIONS.items()}


cdef inline cnp.ndarray _output(_Function f, int k, bint batch, cnp.npy_intp n):
    """A new array for output ``k`` of ``f``: its row shape, after ``n`` rows for a batch."""
    cdef cnp.npy_intp dims[MAX_DIMS]
    cdef int j, nd = 0
    if batch:
        dims[0] = n
        nd = 1
    for j in range(f.ndims[k]):
        dims[nd] = f.dims[k][j]
        nd += 1
    return cnp.PyArray_EMPTY(nd, dims, cnp.NPY_DOUBLE, 0)


cdef inline void _batch_call(const stewart_params *p, stewart_call fn, Py_ssize_t start, Py_ssize_t count,
                             int nin, const double **ins, double scalar, int nout, double **outs,
                             const int *widths, int *status) noexcept nogil:
    """Rows start ... start + count - 1 of a batch through the function ``fn``: its ``nin``
    input arrays ``ins`` (6 doubles a row) and ``nout`` output arrays ``outs`` (``widths``)."""
    cdef const double *i[STEWART_MAX_INPUTS]
    cdef double *o[STEWART_MAX_OUTPUTS]
    cdef int k
    for k in range(nin):
        i[k] = ins[k] + 6 * start
    for k in range(nout):
        o[k] = outs[k] + widths[k] * start
    fn(p, count, i, scalar, o, status + start)


cdef Py_ssize_t _batch_block(int nin, int nout, const int *widths) noexcept nogil:
    """Rows a thread takes at a time from a batch function: BATCH_BYTES of their inputs,
    outputs and statuses, in whole blocks of LANES rows."""
    cdef Py_ssize_t k, row = 6 * nin * sizeof(double) + sizeof(int)
    for k in range(nout):
        row += widths[k] * sizeof(double)
    return max(1, BATCH_BYTES // row // C_LANES) * C_LANES


@cython.final
cdef class Kernel:
    """The compiled model for one parameter set. ``threads`` > 1 splits batches over
    that many threads.

    :meth:`call` runs any public function of the C model (stewart._generated.FUNCTIONS) on
    one state or a batch; each is also a method of its name (``kernel.inverse_dynamics(x, xd,
    xdd, return_mask=False)``; the RK4 step ``kernel.rk4_step(x, xd, tau, dt, jacobians=False,
    return_mask=False)``)."""

    def __cinit__(self, params, threads=1):
        stewart_params_fill(&self.p, params, _PARAM_NAMES)
        self.threads = arguments.thread_count(threads)

    def call(self, str name, tuple arrays, bint return_mask=False, double scalar=0.0):
        """The public function ``name`` of the C model on the tuple ``arrays``, its inputs (each
        one state ``(6,)`` or a batch ``(N, 6)``; a row broadcasts against a batch), with its
        scalar input ``scalar`` (the RK4 step's ``dt``): its one result, or the tuple of its
        results, each of shape ``(N,) +`` its row shape for a batch; with ``return_mask``,
        ``(result, ok)``. (All positional, the cheapest call from Python.)"""
        cdef _Function f = _FUNCTIONS.get(name)
        if f is None:
            raise ValueError(f"no function {name!r} in the C model; its functions: {', '.join(_FUNCTIONS)}")
        if len(arrays) != f.nin:
            raise TypeError(f"{name} takes {f.nin} array(s) ({', '.join(f.inputs)}), got {len(arrays)}")
        return self._run(f, arrays, scalar, return_mask)

    def __getattr__(self, str name):
        """The public functions of the C model as methods (stewart._generated.FUNCTIONS: each
        function under its method's name)."""
        entry = _METHODS.get(name)
        if entry is None:
            raise AttributeError(f"'Kernel' object has no attribute {name!r}")
        return _Method(self, *entry)

    def __dir__(self):
        return sorted(set(object.__dir__(self)) | _METHODS.keys())

    cdef object _run(self, _Function f, tuple values, double scalar, bint return_mask):
        """Evaluate ``f`` on one state (its batch function on one row) or on a batch (in
        blocks of rows, split over threads if asked), the inputs ``values`` checked and
        converted, its outputs made; its result, or the errors of its failed rows."""
        cdef cnp.ndarray arr, status
        cdef const double *ins[STEWART_MAX_INPUTS]
        cdef double *outs[STEWART_MAX_OUTPUTS]
        cdef int *ps
        cdef int status1 = 0
        cdef cnp.npy_intp n = 1
        cdef bint batch = False
        cdef Py_ssize_t block, failures
        cdef int k, nin = f.nin, nout = f.nout
        cdef stewart_call fn = T.call[f.index]

        # The inputs as C arrays: ``values`` itself when each is one already (no new object).
        arrays = values
        for k in range(nin):
            arr = _states(f.inputs[k], values[k])
            if arr is not values[k]:
                if arrays is values:
                    arrays = list(values)
                arrays[k] = arr
        for k in range(nin):
            arr = <cnp.ndarray>arrays[k]
            if arr.ndim == 2:
                if batch and arr.shape[0] != n:
                    raise ValueError("arguments must have matching batch shapes: "
                                     + ", ".join(f"{nm} {np.shape(v)}" for nm, v in zip(f.inputs, values)))
                batch, n = True, arr.shape[0]
        # The outputs: the one array, or a tuple of them.
        if nout == 1:
            outputs = arr = _output(f, 0, batch, n)
            outs[0] = <double *>cnp.PyArray_DATA(arr)
        else:
            outputs = PyTuple_New(nout)
            for k in range(nout):
                arr = _output(f, k, batch, n)
                outs[k] = <double *>cnp.PyArray_DATA(arr)
                Py_INCREF(arr)
                PyTuple_SET_ITEM(outputs, k, arr)

        if batch:
            arrays = list(arrays)
            for k in range(nin):
                arr = <cnp.ndarray>arrays[k]
                if arr.ndim == 1:  # the batch function takes whole arrays: a row broadcast is copied
                    arr = np.ascontiguousarray(np.broadcast_to(arr, (n, 6)))
                    arrays[k] = arr
                ins[k] = <const double *>cnp.PyArray_DATA(arr)
            status = cnp.PyArray_ZEROS(1, &n, cnp.NPY_INT, 0)
            ps = <int *>cnp.PyArray_DATA(status)
            block = _batch_block(nin, nout, f.widths)
            if self.threads > 1 and n > block and not STEWART_OPENMP:
                self._threads(fn, f, n, block, ins, scalar, outs, ps)
            else:
                with nogil:
                    self._batch(fn, f, n, block, ins, scalar, outs, ps)
            failures = np.count_nonzero(status)
        else:
            for k in range(nin):
                ins[k] = <const double *>cnp.PyArray_DATA(<cnp.ndarray>arrays[k])
            status1 = fn(&self.p, 1, ins, scalar, outs, NULL)
            failures = status1 != STEWART_OK
            status = None
        result = outputs if f.whole else f.split((outputs,) if nout == 1 else outputs)
        if failures == 0:
            return (result, np.ones(n, dtype=bool) if batch else True) if return_mask else result
        if status is None:
            status = np.array([status1], dtype=np.intc)
        return self._failed(f, tuple(arrays), result, status, batch, return_mask)

    cdef void _batch(self, stewart_call fn, _Function f, Py_ssize_t n, Py_ssize_t block, const double **ins,
                     double scalar, double **outs, int *status) noexcept nogil:
        """``fn`` on n rows, in blocks of ``block`` rows split over OpenMP threads (one thread
        without OpenMP)."""
        cdef Py_ssize_t b, start, count, nblocks = (n + block - 1) // block
        if self.threads > 1 and nblocks > 1:
            for b in prange(nblocks, num_threads=self.threads, schedule="dynamic"):
                start = b * block
                count = min(block, n - start)
                _batch_call(&self.p, fn, start, count, f.nin, ins, scalar, f.nout, outs, f.widths, status)
        else:
            _batch_call(&self.p, fn, 0, n, f.nin, ins, scalar, f.nout, outs, f.widths, status)

    cdef int _threads(self, stewart_call fn, _Function f, Py_ssize_t n, Py_ssize_t block, const double **ins,
                      double scalar, double **outs, int *status) except -1:
        """The n rows split over plain threads (a build without OpenMP) in blocks of ``block``
        rows, through ``fn``."""
        cdef int k
        cdef _Blocks blocks = _Blocks(self, f, scalar, n, block)
        blocks.fn, blocks.status = fn, status
        for k in range(f.nin):
            blocks.ins[k] = ins[k]
        for k in range(f.nout):
            blocks.outs[k] = outs[k]
        with ThreadPoolExecutor(self.threads) as pool:
            list(pool.map(blocks.run, range(self.threads), [self.threads] * self.threads))
        return 0

    cdef object _failed(self, _Function f, tuple arrays, object out, cnp.ndarray status, bint batch,
                        bint return_mask):
        # The C reports a row with a non-finite input as STEWART_ERR_NONFINITE.
        if np.any(status == STEWART_ERR_NONFINITE):
            for name, arr in zip(f.inputs, arrays):
                arguments.finite_states(name, arr)
        rows = np.flatnonzero(status != STEWART_OK)
        if return_mask:
            return out, (status == STEWART_OK) if batch else bool(status[0] == STEWART_OK)
        condition, message, _ = CONDITIONS[status[rows[0]]]
        raise SingularityError.at_rows(f.name, condition, message, rows.tolist(), batch)

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

    def friction_forces(self, rates, law):
        """The forces the legs lose to friction (the C model's law, stewart_batch_friction_forces)
        at the leg rates ``rates`` (``(6,)`` or ``(N, 6)``, C-contiguous float64) for the law
        ``(F_v (6,), F_c (6,), v_c)``: an array of the shape of ``rates``, NaN in a row whose
        rates or forces are not finite."""
        cdef cnp.ndarray crates = _c_array("rates", rates, cnp.NPY_DOUBLE, np.ndim(rates), False)
        cdef cnp.ndarray out = np.empty_like(crates)
        cdef stewart_friction f = as_friction("law", law)
        cdef size_t n = crates.size // 6
        with nogil:
            T.batch_friction_forces(&f, n, <const double *>cnp.PyArray_DATA(crates), <double *>cnp.PyArray_DATA(out),
                                    NULL)
        return out


@cython.final
cdef class _Method:
    """A public function of the C model as a method of a Kernel: ``(*arrays, [scalar,]
    [option=False,] return_mask=False)``, the arrays and the scalar (if the function has one)
    named as the function's inputs; with ``option`` true, the function ``optional``."""
    cdef Kernel kernel
    cdef _Function plain, optional
    cdef str option

    def __cinit__(self, Kernel kernel, _Function plain, str option, _Function optional):
        self.kernel, self.plain, self.option, self.optional = kernel, plain, option, optional

    def __call__(self, *args, **kwargs):
        f = self.plain
        names = f.inputs + ((f.scalar,) if f.scalar else ()) + ((self.option,) if self.option else ()) + ("return_mask",)
        required = f.nin + bool(f.scalar)
        if len(args) > len(names):
            raise TypeError(f"{f.name} takes at most {len(names)} arguments ({', '.join(names)}), got {len(args)}")
        bound = dict(zip(names, args))
        for key, value in kwargs.items():
            if key not in names or key in bound:
                raise TypeError(f"{f.name}: {'unexpected' if key not in names else 'repeated'} argument {key!r}")
            bound[key] = value
        missing = [name for name in names[:required] if name not in bound]
        if missing:
            raise TypeError(f"{f.name}: missing argument(s) {', '.join(missing)}")
        if self.option and bound.get(self.option, False):
            f = self.optional
        return self.kernel._run(f, tuple(bound[name] for name in f.inputs), bound[f.scalar] if f.scalar else 0.0,
                                bound.get("return_mask", False))


def _methods():
    """{method: (its function, its option or '', the function with the option true or None)}."""
    methods = {}
    for name, spec in FUNCTIONS.items():
        if not spec.option:
            methods[spec.method] = [_FUNCTIONS[name], "", None]
    for name, spec in FUNCTIONS.items():
        if spec.option:
            methods[spec.method][1:] = [spec.option, _FUNCTIONS[name]]
    return {method: tuple(entry) for method, entry in methods.items()}


#: {method: (function, option, function with the option)} of the Kernel's methods.
cdef dict _METHODS = _methods()


@cython.final
cdef class _Blocks:
    """A batch split over plain threads (a build without OpenMP): thread ``k`` of ``m`` runs
    blocks k, k + m, ... of ``block`` rows without the GIL, through the batch function."""
    cdef Kernel kernel
    cdef _Function f
    cdef stewart_call fn
    cdef double scalar
    cdef Py_ssize_t n, block
    cdef const double *ins[STEWART_MAX_INPUTS]
    cdef double *outs[STEWART_MAX_OUTPUTS]
    cdef int *status

    def __cinit__(self, Kernel kernel, _Function f, double scalar, Py_ssize_t n, Py_ssize_t block):
        self.kernel, self.f, self.scalar, self.n, self.block = kernel, f, scalar, n, block

    def run(self, Py_ssize_t first, Py_ssize_t step):
        """Run blocks ``first``, ``first + step``, ...."""
        cdef Py_ssize_t start
        with nogil:
            start = first * self.block
            while start < self.n:
                _batch_call(&self.kernel.p, self.fn, start, min(self.block, self.n - start), self.f.nin,
                            self.ins, self.scalar, self.f.nout, self.outs, self.f.widths, self.status)
                start += step * self.block


include "_simulate.pxi"
include "_envelope.pxi"
include "_modes.pxi"
include "_rotary.pxi"
include "_rotary_envelope.pxi"
include "_cueing.pxi"
include "_cueing_rows.pxi"
