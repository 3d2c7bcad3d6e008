"""Exact, reproducible descriptions of values: the keys of the overkill
cache (:mod:`skfem_pg.scenes`) and the fingerprints of checkpoints
(:mod:`skfem_pg.solvers.checkpoint`) are built from them.

Floats enter by their hex form (one ulp makes another key), arrays of
more than 8 numbers by a hash of their bytes, objects (a material and the
hardening and damage laws it holds) by their type and public attributes
(private ones are caches and committed state, not parameters), functions
by their byte code, constants, defaults and closure values; no memory
addresses.

>>> import numpy as np
>>> from skfem_pg.keys import exact
>>> exact(0.45) == exact(0.45), exact(0.45) == exact(np.nextafter(0.45, 1))
(True, False)
"""
import hashlib

import numpy as np


def digest(a):
    """``"shape sha1"`` of an array's values (as floats)."""
    a = np.ascontiguousarray(np.asarray(a, dtype=float))
    return "{} {}".format(a.shape, hashlib.sha1(a.tobytes()).hexdigest()[:16])


def exact(v, depth=0):
    """A reproducible description of ``v``, exact to the bit (module
    docstring); nesting deeper than 8 objects falls back to ``repr``."""
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    if isinstance(v, (float, np.floating)):
        return float(v).hex()
    if isinstance(v, (int, np.integer)):
        return int(v)
    if isinstance(v, (str, type(None))):
        return v
    if isinstance(v, np.ndarray):
        if v.size > 8 and v.dtype.kind in "biuf":
            return digest(v)
        return [exact(a, depth + 1) for a in v.ravel().tolist()] \
            + [list(v.shape)]
    if isinstance(v, dict):
        return sorted((str(k), exact(a, depth + 1)) for k, a in v.items())
    if isinstance(v, (list, tuple)):
        return [exact(a, depth + 1) for a in v]
    if callable(v) and not hasattr(v, "__dict__") or \
            hasattr(v, "__code__"):
        return callable_key(v)
    if hasattr(v, "__dict__") and depth < 8:
        return (type(v).__module__, type(v).__qualname__,
                exact({k: a for k, a in vars(v).items()
                       if not k.startswith("_")}, depth + 1))
    return repr(v)


def callable_key(f):
    """A function by its module, name, byte code, constants, defaults and
    closure values (no memory addresses)."""
    code = getattr(f, "__code__", None)
    if code is None:
        return repr(type(f))

    def value(c):
        if callable(c):
            return callable_key(c)
        if isinstance(c, np.ndarray):
            return digest(c)
        return repr(c)
    cells = [value(c.cell_contents) for c in (f.__closure__ or ())]
    return (getattr(f, "__module__", ""), getattr(f, "__qualname__", ""),
            hashlib.sha1(code.co_code).hexdigest(),
            repr(code.co_consts), repr(code.co_names),
            [value(c) for c in (f.__defaults__ or ())], cells)


__all__ = ["callable_key", "digest", "exact"]
