"""CLI: regenerate generated/: the model's header stewart_model.h, its units (stewart_model.c, the
public functions, and stewart_model_<family>.c, the kernels of one family each) with what they
share (stewart_internal.h), its Cython declarations stewart_model.pxd, and the dispatch between
compiled copies of the model, stewart_dispatch.h and stewart_target.c; and the tables the Python
layer reads, the module stewart/_generated.py; and the rotary family's (codegen/rotary_source.py).
Files of an earlier generation that it no longer writes (stewart_model_*.c, stewart_rotary_*.c)
are removed."""

import argparse
import dataclasses
import os
import time
from concurrent.futures import ProcessPoolExecutor
from functools import partial
from pathlib import Path

from . import csource, emit, kinematics, model, pxd, pymodule, rotary, rotary_source, schema

DEFAULT_OUT = Path(__file__).resolve().parent.parent / 'generated'
DEFAULT_PYTHON = Path(__file__).resolve().parent.parent / 'stewart' / '_generated.py'
#: The rotary family's tables (codegen/rotary_source.py), beside --python.
ROTARY_PYTHON = '_generated_rotary.py'


def _timed(func, *args):
    start = time.perf_counter()
    result = func(*args)
    return result, time.perf_counter() - start


def _write_if_changed(path, text):
    """Write ``text`` to ``path`` unless it holds exactly that already (then the file, and its
    modification time, stay as they are, so builds that depend on it do not rerun)."""
    data = text.encode('ascii')
    if path.is_file() and path.read_bytes() == data:
        return False
    path.write_bytes(data)
    return True


def _kernel(build, params=kinematics.PARAMS, params_type='stewart_params'):
    """Derive and emit one kernel on the parameter symbols `params` of the C struct `params_type`
    (the linear model's, or the rotary family's `rotary.RPARAMS` of `stewart_rotary_params`):
    (its C, its spec without the derivation graph, the derivation and emission times)."""
    kernel, t_derive = _timed(build)
    result, t_emit = _timed(emit.emit_kernel, kernel, params.members(), params_type)
    return result, dataclasses.replace(kernel, graph=None), t_derive, t_emit


def main(argv=None):
    parser = argparse.ArgumentParser(prog='python -m codegen', description=__doc__)
    parser.add_argument('--out', type=Path, default=DEFAULT_OUT,
                        help='output directory (default: %(default)s)')
    parser.add_argument('--python', type=Path, default=DEFAULT_PYTHON,
                        help='the Python module of the tables (default: %(default)s)')
    parser.add_argument('--jobs', type=int, default=os.cpu_count() or 1,
                        help='processes deriving the kernels side by side (default: %(default)s)')
    args = parser.parse_args(argv)

    total = time.perf_counter()
    generated = [f for f in model.FUNCTIONS if not f.template]
    # Every kernel once, in the order the functions first use it.
    builders = list(dict.fromkeys(
        build for function in generated
        for build in list(function.kernels) + [b for step in function.steps if isinstance(step, model.Kernels)
                                               for b in step.builders]))
    emitted, kernels, families = [], {}, {}
    # The kernels are independent: derive them side by side, collect them in their order.
    with ProcessPoolExecutor(max(1, args.jobs)) as pool:
        for build, (result, kernel, t_derive, t_emit) in zip(builders, pool.map(_kernel, builders)):
            kernels[build] = kernel
            emitted.append(result)
            families.setdefault(csource.kernel_family(build), []).append(result)
            print(f'[codegen] {kernel.name:<32} derive {t_derive:5.2f} s, cse+C {t_emit:5.2f} s,'
                  f' {result.ops:5d} ops', flush=True)
        rotary_emitted, rotary_kernels = [], {kinematics.euler_maps_kernel: kernels[kinematics.euler_maps_kernel]}
        rotary_kernel = partial(_kernel, params=rotary.RPARAMS, params_type='stewart_rotary_params')
        for build, (result, kernel, t_derive, t_emit) in zip(rotary_source.BUILDERS,
                                                             pool.map(rotary_kernel, rotary_source.BUILDERS)):
            rotary_kernels[build] = kernel
            rotary_emitted.append(result)
            print(f'[codegen] {kernel.name:<32} derive {t_derive:5.2f} s, cse+C {t_emit:5.2f} s,'
                  f' {result.ops:5d} ops', flush=True)
    public = [csource.public_function(function) for function in model.FUNCTIONS]
    batch = [csource.batch_function(function, kernels) for function in model.FUNCTIONS]

    start = time.perf_counter()
    args.out.mkdir(parents=True, exist_ok=True)
    ops = [(k.name, k.ops) for k in emitted]
    files = {
        'stewart_model.h': csource.header(schema.PARAM_FIELDS, model.FUNCTIONS, ops, schema.INERTIAL_PARAMETERS),
        'stewart_internal.h': csource.internal_header(schema.PARAM_FIELDS, model.FUNCTIONS, emitted),
        'stewart_model.c': csource.source(public, batch),
        **{f'stewart_model_{family}.c': csource.kernel_unit(family, units) for family, units in families.items()},
        'stewart_model.pxd': pxd.pxd(schema.PARAM_FIELDS, model.FUNCTIONS),
        'stewart_dispatch.h': csource.dispatch_header(model.FUNCTIONS, rotary_source.FUNCTIONS),
        'stewart_target.c': csource.target_source(model.FUNCTIONS),
        'stewart_rotary.h': rotary_source.header([(k.name, k.ops) for k in rotary_emitted]),
        'stewart_rotary_internal.h': rotary_source.internal_header(rotary_emitted),
        'stewart_rotary.c': rotary_source.source(rotary_kernels),
        **{f'stewart_{k.name}.c': rotary_source.kernel_unit(k) for k in rotary_emitted},
        'stewart_rotary_dispatch.h': rotary_source.dispatch_header(),
        'stewart_rotary.pxd': rotary_source.pxd(),
    }
    written = [name for name, text in files.items() if _write_if_changed(args.out / name, text)]
    python = pymodule.module(schema.PARAM_FIELDS, schema.LEFT_OUT, model.FUNCTIONS, schema.INERTIAL_PARAMETERS)
    args.python.parent.mkdir(parents=True, exist_ok=True)
    if _write_if_changed(args.python, python):
        written.append(str(args.python))
    if _write_if_changed(args.python.parent / ROTARY_PYTHON, rotary_source.module()):
        written.append(str(args.python.parent / ROTARY_PYTHON))
    for stale in sorted(set(p.name for pattern in ('stewart_model_*.c', 'stewart_rotary_*.c')
                            for p in args.out.glob(pattern)) - files.keys()):
        (args.out / stale).unlink()
        written.append(f'{stale} removed')
    print(f'[codegen] write {args.out} ({", ".join(written) or "unchanged"}) ...'
          f' {time.perf_counter() - start:.2f} s')
    print(f'[codegen] total ... {time.perf_counter() - total:.2f} s')


if __name__ == '__main__':
    main()
