# The rotary family's array mover (issue 40), included by stewart/_kernel.pyx: the rotary
# functions of the generated C (generated/stewart_rotary.h; their table
# stewart_rotary_dispatch.h, one per compiled copy of the model, the copy in use the one of the
# linear model's path) on one state or a batch, the GIL released, through the same batch
# calls as the linear model's (_batch_call: the rotary parameters go as an opaque pointer).

from libc.string cimport strcmp

from stewart_rotary cimport *

from ._generated_rotary import CRANK_CONDITIONS, FUNCTIONS as ROTARY_FUNCTIONS

#: {name: _Function} of every rotary function (stewart._generated_rotary.FUNCTIONS).
cdef dict _ROTARY = {name: _Function(name, spec) for name, spec in ROTARY_FUNCTIONS.items()}
#: The status codes of the rotary functions: the linear model's and the cranks'.
cdef dict _ROTARY_CONDITIONS = {**CONDITIONS, **CRANK_CONDITIONS}


cdef const stewart_rotary_table *_rotary_table() except NULL:
    """The rotary table of the compiled copy in use (the linear table's path, T)."""
    cdef int i = 0
    while stewart_rotary_tables[i] != NULL:
        if strcmp(stewart_rotary_tables[i].name, T.name) == 0:
            return stewart_rotary_tables[i]
        i += 1
    raise ImportError(f"no rotary table for the compiled path {T.name.decode()}: rebuild")


@cython.final
cdef class RotaryKernel:
    """The compiled rotary model for one stewart.RotaryParams: :meth:`call` runs a rotary
    function (stewart._generated_rotary.FUNCTIONS) on one state ``(6,)`` or a batch
    ``(N, 6)`` (a row broadcasts against a batch)."""
    cdef stewart_rotary_params p

    def __cinit__(self, params):
        stewart_rotary_params_fill(&self.p, params)

    def call(self, str name, tuple arrays, bint return_mask=False, double scalar=0.0):
        """The rotary function ``name`` on ``arrays``, its inputs, with its scalar input
        ``scalar`` (the RK4 step's ``dt``; ignored by a function without one): its result (each
        of shape ``(N,) +`` its row shape for a batch); with ``return_mask``, ``(result, ok)``.
        SingularityError naming the rows that fail, without ``return_mask``."""
        cdef _Function f = _ROTARY.get(name)
        cdef const double *ins[STEWART_MAX_INPUTS]
        cdef double *outs[STEWART_MAX_OUTPUTS]
        cdef cnp.ndarray arr, status
        cdef cnp.npy_intp n = 1
        cdef bint batch = False
        cdef int k
        cdef stewart_call fn
        if f is None:
            raise ValueError(f"no rotary function {name!r}; its functions: {', '.join(_ROTARY)}")
        if len(arrays) != f.nin:
            raise TypeError(f"{name} takes {f.nin} array(s) ({', '.join(f.inputs)}), got {len(arrays)}")
        fn = _rotary_table().call[f.index]
        values = [_states(f.inputs[k], arrays[k]) for k in range(f.nin)]
        for k in range(f.nin):
            if values[k].ndim == 2:
                if batch and values[k].shape[0] != n:
                    raise ValueError("arguments must have matching batch shapes: "
                                     + ", ".join(f"{nm} {np.shape(v)}" for nm, v in zip(f.inputs, arrays)))
                batch, n = True, values[k].shape[0]
        for k in range(f.nin):
            if batch and values[k].ndim == 1:
                values[k] = np.ascontiguousarray(np.broadcast_to(values[k], (n, 6)))
            ins[k] = <const double *>cnp.PyArray_DATA(<cnp.ndarray>values[k])
        outputs = []
        for k in range(f.nout):
            arr = _output(f, k, batch, n)
            outs[k] = <double *>cnp.PyArray_DATA(arr)
            outputs.append(arr)
        status = cnp.PyArray_ZEROS(1, &n, cnp.NPY_INT, 0)
        cdef int *ps = <int *>cnp.PyArray_DATA(status)
        with nogil:
            fn(<const stewart_params *>&self.p, n, ins, scalar, outs, ps)
        result = outputs[0] if f.whole and f.nout == 1 else (tuple(outputs) if f.whole else f.split(tuple(outputs)))
        ok = status == STEWART_OK
        if return_mask:
            return result, ok if batch else bool(ok[0])
        if not ok.all():
            if np.any(status == STEWART_ERR_NONFINITE):
                for nm, v in zip(f.inputs, values):
                    arguments.finite_states(nm, v)
            rows = np.flatnonzero(~ok)
            condition, message, _ = _ROTARY_CONDITIONS[status[rows[0]]]
            raise SingularityError.at_rows(f"rotary {f.name}", condition, message, rows.tolist(), batch)
        return result
