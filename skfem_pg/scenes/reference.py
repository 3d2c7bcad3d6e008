"""FE overkill references: a scene solved on a refined mesh with a
quadratic element, cached on disk, and evaluated anywhere.

The cache key is :meth:`Scene.fingerprint`: a hash of everything that
defines the problem — mesh vertices, elements and named boundaries, probes,
material type and parameters and loads at full precision — and of the
refinement and element, so a changed problem never reuses a stale
reference.  Files live in ``$SKFEM_PG_CACHE`` (default
``~/.cache/skfem_pg``); they are written atomically (temporary file, then
rename), an unreadable entry is recomputed with a warning naming it, and a
cache that cannot be written warns and still returns the reference.
"""
import hashlib
import os
import re
import time
import warnings
import zipfile

import numpy as np
import skfem as fem

from ..formulations.linear import linear_elasticity
from .meshing import cook_membrane
from .. import registry
from ..io import atomic_write
from .scene import centroid_tree, inside
from ..keys import exact

QUADRATIC = {"T1": "T2", "Q1": "Q2", "O1": "O2", "H1": "H2"}


#: bump when the stored content changes meaning (3: prescribed components
#: of quadratic elements constrain their facet dofs too; 4: the key holds
#: the callable loads' values, the load steps and the solve keywords, the
#: file its format and a checksum of its content; 5: nested laws and
#: solve keywords in the key by their exact values, not their repr; 6:
#: :func:`skfem_pg.keys.exact`, without the laws' private caches)
CACHE_FORMAT = 6


def cache_dir():
    """``$SKFEM_PG_CACHE`` or ``~/.cache/skfem_pg`` (not created here)."""
    return os.environ.get("SKFEM_PG_CACHE",
                          os.path.join(os.path.expanduser("~"), ".cache",
                                       "skfem_pg"))


def _checksum(arrays):
    """SHA-1 of the named arrays (names, shapes, dtypes and bytes)."""
    h = hashlib.sha1()
    for k in sorted(arrays):
        a = np.ascontiguousarray(arrays[k])
        h.update("{} {} {}".format(k, a.shape, a.dtype).encode())
        h.update(a.tobytes())
    return h.hexdigest()


#: what an unreadable cache entry raises (then it is recomputed)
UNREADABLE = (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile)


def _read(fn):
    """The arrays of the cache entry ``fn`` (written by :func:`_store`);
    ``ValueError`` if its format or checksum (an edited file) does not
    fit."""
    with np.load(fn) as data:
        arrays = {k: data[k] for k in data.files}
    fmt = arrays.pop("format", None)
    if fmt is None or int(fmt) != CACHE_FORMAT:
        raise ValueError("format {} where {} is expected".format(
            None if fmt is None else int(fmt), CACHE_FORMAT))
    stored = str(arrays.pop("checksum", ""))
    if stored != _checksum(arrays):
        raise ValueError("its checksum does not match its content")
    return arrays


def _load(fn, mesh_type, method, probes):
    """The stored :class:`Reference`; ``ValueError`` naming what does not
    fit: format, checksum, the solution's length for ``method`` on the
    stored mesh, the probe names."""
    arrays = _read(fn)
    got = {k[6:]: v for k, v in arrays.items() if k.startswith("probe_")}
    if sorted(got) != sorted(probes):
        raise ValueError("probes {} where the scene has {}".format(
            sorted(got), sorted(probes)))
    ref = Reference(mesh_type(arrays["p"], arrays["t"]), method,
                    arrays["u"], got)
    if arrays["u"].shape != (ref.basis.N,):
        raise ValueError("u has shape {}, {} on its mesh needs ({},)".format(
            arrays["u"].shape, method, ref.basis.N))
    return ref


def cache_name(name):
    """A scene name as a file name part: letters, digits, ``-``, ``_`` and
    ``.`` kept, anything else (path separators, ``..``) replaced by
    ``_`` — no name writes outside :func:`cache_dir`."""
    safe = re.sub(r"[^A-Za-z0-9_.-]", "_", str(name)).lstrip(".")
    return safe.replace("..", "_") or "scene"


def _store(fn, **arrays):
    """Write ``fn`` atomically; warn (and return False) if it cannot be
    written."""
    d = os.path.dirname(fn)
    arrays = dict(arrays, checksum=_checksum(arrays), format=CACHE_FORMAT)
    try:
        os.makedirs(d, exist_ok=True)
        atomic_write(fn, lambda f: np.savez(f, **arrays))
    except OSError as err:
        warnings.warn("could not write the overkill reference cache {} "
                      "({}); the reference is used but not kept".format(
                          fn, err))
        return False
    return True


class Reference:
    """A stored FE solution that evaluates displacements and gradients at
    arbitrary points (``(d, n)``) inside its mesh."""

    def __init__(self, mesh, method, u, probes):
        self.mesh, self.method, self.u = mesh, method, u
        self.probes = probes
        self.basis = fem.Basis(mesh, fem.ElementVector(
            registry.fe_method(method).element()))
        self._finder = mesh.element_finder()
        self._tree = centroid_tree(mesh)

    def _inside(self, x):
        return inside(self.mesh, x, self._tree)

    def evaluate(self, x):
        """``(values (d, n), gradients (d, d, n))`` at points ``x``."""
        x = self._inside(np.asarray(x, float))
        tind = self._finder(*x)
        mapping = self.basis.mapping
        X = mapping.invF(x[:, :, None], tind=tind)
        d = x.shape[0]
        val = np.zeros((d, x.shape[1]))
        grad = np.zeros((d, d, x.shape[1]))
        elem = self.basis.elem
        dofs = self.basis.element_dofs[:, tind]
        for i in range(self.basis.Nbfun):
            phi = elem.gbasis(mapping, X, i, tind=tind)[0]
            c = self.u[dofs[i]]
            val += c * np.asarray(phi)[..., 0]
            grad += c * phi.grad[..., 0]
        return val, grad

    def errors(self, particles, u):
        """Discrete L2 error at the particles,
        :math:`(\\sum_p V^p |u^p - u_{ref}(X^p)|^2)^{1/2}`, and the same
        norm of the reference (for relative errors)."""
        act = particles.active
        ref, _ = self.evaluate(particles.x[:, act])
        e = u.reshape(-1, particles.dim).T[:, act] - ref
        V = particles.volumes[act]
        return (float(np.sqrt(np.sum(V * (e ** 2).sum(0)))),
                float(np.sqrt(np.sum(V * (ref ** 2).sum(0)))))


def overkill(scene, refine=2, method=None, verbose=True, **solve_kwargs):
    """Solve ``scene`` on its mesh refined ``refine`` times with the
    quadratic element of its mesh type (or ``method``); cached under
    :meth:`Scene.fingerprint` of the problem, ``refine``, ``method`` and
    every ``solve_kwargs`` (a tolerance makes another reference).  A
    cached entry is used only if its format, checksum, solution length
    and probe names fit; otherwise it is recomputed with a warning."""
    base = {fem.MeshTri1: "T1", fem.MeshQuad1: "Q1", fem.MeshTet1: "O1",
            fem.MeshHex1: "H1"}[type(scene.mesh)]
    method = method or QUADRATIC[base]
    key = scene.fingerprint(refine, method, CACHE_FORMAT,
                            exact(solve_kwargs))
    fn = os.path.join(cache_dir(), "{}-{}.npz".format(cache_name(scene.name),
                                                      key[:20]))
    mesh = scene.mesh.refined(refine) if refine else scene.mesh
    if os.path.exists(fn):
        try:
            return _load(fn, type(scene.mesh), method, scene.probes)
        except UNREADABLE as err:
            warnings.warn("the cached overkill reference {} is unreadable "
                          "({}: {}); recomputing it".format(
                              fn, type(err).__name__, err))
    if verbose:
        print("  computing the {} overkill reference on {} elements (a "
              "first-run cost: it is cached in {}) ...".format(
                  method, mesh.nelements, cache_dir()), flush=True)
    t0 = time.perf_counter()
    res = scene.solve(method, mesh=mesh, **solve_kwargs)
    _store(fn, p=mesh.p, t=mesh.t, u=res.u,
           **{"probe_" + k: v for k, v in res.probes.items()})
    if verbose:
        print("  overkill computed and cached in {:.1f} s".format(
            time.perf_counter() - t0), flush=True)
    return Reference(mesh, method, res.u, res.probes)


def linear_cook(lam, mu, sizes=(64, 128), point=(48.0, 52.0),
                verbose=True):
    """The vertical displacement at ``point`` of the linear Cook's membrane
    (:func:`~skfem_pg.scenes.meshing.cook_membrane`; clamped at x = 0, a
    total shear load 1 on x = 48; Lamé ``lam``, ``mu``): Q2 on the n×n
    meshes of the two ``sizes``, Richardson-extrapolated with rate 2
    (observed about 1.4: the corner singularity; 2 underestimates the
    correction).  Returns ``(v, (v_coarse, v_fine))``, cached in
    :func:`cache_dir` (atomic writes, checksum; the key holds every
    argument).  With E = 1, nu = 1/3 in plane stress and sizes 64, 128:
    23.96723 (literature 23.96)."""
    args = np.array([lam, mu, *sizes, *point], dtype=float)
    key = hashlib.sha1(args.tobytes()).hexdigest()[:16]
    fn = os.path.join(cache_dir(), "linear-cook-{}.npz".format(key))
    if os.path.exists(fn):
        try:
            arrays = _read(fn)
            if not np.array_equal(arrays["args"], args):
                raise ValueError("its key is another problem's")
            return float(arrays["v"]), tuple(arrays["q2"])
        except UNREADABLE as err:
            warnings.warn("the reference cache {} is unreadable ({}: {}); "
                          "recomputing it".format(fn, type(err).__name__,
                                                  err))
    form = linear_elasticity(lam, mu)
    if verbose:
        print("  computing the linear Cook Q2 reference (a first-run cost: "
              "it is cached in {}) ...".format(cache_dir()), flush=True)
    vals = []
    for n in sizes:
        m = cook_membrane(n)
        e = fem.ElementVector(fem.ElementQuad2())
        b = fem.Basis(m, e)
        fb = fem.FacetBasis(m, e, facets="right")
        f = fem.LinearForm(lambda v, w: v[1] / 16.0).assemble(fb)
        u = fem.solve(*fem.condense(form.assemble(b), f,
                                    D=b.get_dofs("left")))
        vals.append(float((b.probes(np.array(point)[:, None]) @ u)[1]))
        if verbose:
            print("  Q2 overkill {0}x{0}: v = {1:.5f}".format(n, vals[-1]))
    v = vals[1] + (vals[1] - vals[0]) / (2.0 ** 2 - 1.0)
    _store(fn, args=args, v=np.array(v), q2=np.array(vals))
    return v, tuple(vals)

