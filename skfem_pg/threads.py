"""BLAS threads in the batched small-matrix kernels.

The kernels of this package (shape functions, corrections, batched local
matrices, material laws) multiply and invert millions of 3×3 … 81×81
matrices.  A multi-threaded BLAS (OpenBLAS, MKL) wakes its thread pool for
each of these tiny products; on 2 cores that oversubscription slowed the
test suite several times and flipped timing rankings between identical
runs (benchmarks/README.md, "Measurements behind the defaults").  So
every kernel entry point runs with **one BLAS thread** by default,
through threadpoolctl (which changes the pool of the BLAS already loaded
by NumPy at run time; environment variables only act before NumPy is
imported).  Code outside the kernels — the user's own, and
the sparse direct and AMG solvers — keeps the BLAS default.

``SKFEM_PG_BLAS_THREADS`` (environment) or :func:`set_kernel_threads`
chooses the kernels' thread count: a number, or ``"default"`` to leave the
BLAS alone.  :func:`kernel_threads` reports the setting; benchmarks print
it.
"""
import functools
import os
import threading

_state = threading.local()
_setting = {"threads": None}
_controller = {"value": None}


def _parse(value):
    if value is None or value == "":
        return 1
    if str(value).lower() == "default":
        return "default"
    try:
        n = int(value)
    except (TypeError, ValueError):
        raise ValueError("SKFEM_PG_BLAS_THREADS / set_kernel_threads takes a "
                         "positive integer or 'default', got {!r}"
                         .format(value)) from None
    if n < 1:
        raise ValueError("the kernels' BLAS thread count must be >= 1, got "
                         "{}".format(n))
    return n


def kernel_threads():
    """BLAS threads inside the kernels: an int, or ``"default"``."""
    if _setting["threads"] is None:
        _setting["threads"] = _parse(os.environ.get("SKFEM_PG_BLAS_THREADS"))
    return _setting["threads"]


def set_kernel_threads(value):
    """Set the kernels' BLAS thread count (int or ``"default"``); returns
    the previous setting."""
    old = kernel_threads()
    _setting["threads"] = _parse(value)
    return old


def describe():
    """One line for benchmark output: the kernels' setting and the BLAS."""
    try:
        from threadpoolctl import threadpool_info
        libs = ["{} {} ({} threads)".format(i.get("internal_api"),
                                            i.get("version"),
                                            i.get("num_threads"))
                for i in threadpool_info() if i.get("user_api") == "blas"]
    except ImportError:  # pragma: no cover
        libs = ["threadpoolctl not installed"]
    return "BLAS threads in skfem_pg kernels: {}; outside: {}".format(
        kernel_threads(), ", ".join(libs) or "no BLAS found")


def _limiter():
    if _controller["value"] is None:
        from threadpoolctl import ThreadpoolController
        _controller["value"] = ThreadpoolController()
    return _controller["value"]


def kernel(fn):
    """Run ``fn`` with the kernels' BLAS thread count (nested kernels
    share the outermost limit)."""
    @functools.wraps(fn)
    def wrapped(*args, **kwargs):
        n = kernel_threads()
        if n == "default" or getattr(_state, "depth", 0) > 0:
            return fn(*args, **kwargs)
        _state.depth = 1
        try:
            with _limiter().limit(limits=n, user_api="blas"):
                return fn(*args, **kwargs)
        finally:
            _state.depth = 0
    return wrapped
