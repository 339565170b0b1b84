"""CLI: regenerate generated/stewart_model.h, stewart_model.c and stewart_model.pxd."""

import argparse
import os
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from . import csource, emit, model, pxd, schema

DEFAULT_OUT = Path(__file__).resolve().parent.parent / 'generated'


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


def _function(index):
    """Derive and emit the kernels of `model.FUNCTIONS[index]` and write its public C function:
    (its emitted kernels, their derivation and emission times, its public C text)."""
    function = model.FUNCTIONS[index]
    members = model.PARAMS.members()
    kernels, emitted, times = [], [], []
    for build in function.kernels:
        kernel, t_derive = _timed(build)
        result, t_emit = _timed(emit.emit_kernel, kernel, members)
        kernels.append(kernel)
        emitted.append(result)
        times.append((t_derive, t_emit))
    return emitted, times, csource.public_function(function, kernels)


def main(argv=None):
    parser = argparse.ArgumentParser(prog='python -m codegen', description=__doc__)
    parser.add_argument('--out', type=Path, default=DEFAULT_OUT,
                        help='output directory (default: %(default)s)')
    parser.add_argument('--jobs', type=int, default=os.cpu_count() or 1,
                        help='processes deriving the functions side by side (default: %(default)s)')
    args = parser.parse_args(argv)

    total = time.perf_counter()
    emitted, public = [], []
    # The functions are independent: derive them side by side, collect them in their order.
    with ProcessPoolExecutor(max(1, args.jobs)) as pool:
        for kernels, times, text in pool.map(_function, range(len(model.FUNCTIONS))):
            for result, (t_derive, t_emit) in zip(kernels, times):
                print(f'[codegen] {result.name:<28} derive {t_derive:5.2f} s, cse+C {t_emit:5.2f} s,'
                      f' {result.ops:5d} ops', flush=True)
            emitted += kernels
            public.append(text)

    start = time.perf_counter()
    args.out.mkdir(parents=True, exist_ok=True)
    ops = [(k.name, k.ops) for k in emitted]
    files = {
        'stewart_model.h': csource.header(schema.PARAM_FIELDS, model.FUNCTIONS, ops),
        'stewart_model.c': csource.source(schema.PARAM_FIELDS, [k.source for k in emitted], public),
        'stewart_model.pxd': pxd.pxd(schema.PARAM_FIELDS, schema.LEFT_OUT, model.FUNCTIONS),
    }
    written = [name for name, text in files.items() if _write_if_changed(args.out / name, text)]
    print(f'[codegen] write {args.out} ({", ".join(written) or "unchanged"}) ...'
          f' {time.perf_counter() - start:.2f} s')
    print(f'[codegen] total ... {time.perf_counter() - total:.2f} s')


if __name__ == '__main__':
    main()
