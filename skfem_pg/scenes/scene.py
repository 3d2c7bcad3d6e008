"""Benchmark scenes: one problem, solved by PG or by an FE comparator on
the same nodes with one call.

A :class:`Scene` holds a mesh (the node set), a material, clamped and
prescribed boundaries, dead-load tractions and probe points.
``scene.solve("VCBCPBG V5sn UnlP0")`` runs a formulation by its thesis name
(Table 7.1, :mod:`skfem_pg.naming`) on a :class:`~skfem_pg.FamilyBasis`
collocated from the mesh, ``scene.solve("PG", **basis_kwargs)`` the
displacement formulation (VC PBG Unl by default) with basis options,
``scene.solve("PG2")`` the blended quadratic basis on the same vertices
(:mod:`skfem_pg.discretization.blend`; Dirichlet conditions by Nitsche
terms, :class:`~skfem_pg.formulations.WeakDirichlet`), and
``scene.solve("FEM H1P0")`` (or ``"H1P0"``) scikit-fem elements on the same
mesh:

=======  =======================  =========================================
method   mesh                     element
=======  =======================  =========================================
T1       triangles (quads split)  P1
Q1       quadrilaterals           Q1
Q1P0     quadrilaterals           Q1, mean dilatation (iso/vol neo-Hooke)
O1       tetrahedra               P1
H1       hexahedra                Q1
H1P0     hexahedra                Q1, mean dilatation
T2, Q2,  as above                 quadratic (for FE overkill references)
O2, H2
=======  =======================  =========================================

Q1P0 / H1P0 with :meth:`NeoHookeIsoVol.incompressible
<skfem_pg.materials.NeoHookeIsoVol.incompressible>` carry one pressure per
element as an unknown (as PG IUnlP0 does per family).

Every solve reports wall time split into preprocess (basis, families,
corrections), assemble and linear solve (summed over Newton iterations).
A :class:`Result` holds the displacements in scikit-fem numbering of its
basis (``u``) whatever the formulation, its extra fields (``fields``) and
the reaction forces (:meth:`Result.reaction`).
"""
from __future__ import annotations

import hashlib
from typing import Any, NamedTuple, Sequence
import time

import numpy as np
import skfem as fem

from ..discretization.basis import FamilyBasis
from ..discretization.blend import BlendBasis
from ..discretization.follower import FollowerPressure
from ..discretization.loads import (call_user, fe_traction,
                                    traction as pg_traction)
from ..discretization.particles import Particles, linear_elements
from ..formulations.by_name import model_for
from ..formulations.nitsche import WeakDirichlet
from ..formulations.updated_lagrange import UpdatedLagrange
from ..keys import exact
from ..naming import fe_method, formulation_of, frame_of, parse
from ..solvers import newton
from ..solvers.static import external_load
from ..solvers.problem import Problem
from ..solvers.result import Result
from .. import distributed, registry
from ..distributed.solve import DistributedResult
from .meshing import point_index, transfer_boundaries


class Scene:
    """A nonlinear solid-mechanics problem on a node set.

    Parameters
    ----------
    name
        Label (also part of the overkill cache key).
    mesh
        Node set (scikit-fem mesh with named boundaries).
    material
        A :mod:`skfem_pg.materials` law.
    clamped
        Boundary names with ``u = 0``.
    prescribed
        ``{boundary: {component: value}}``: displacement components at
        load factor 1 (scaled by the load factor), or ``{boundary: f}``
        with ``f(x, t)`` the displacement ``(d, n)`` at reference
        positions ``x`` ``(d, n)`` and load factor ``t`` (all components
        prescribed; e.g. a rotation, which is not ``t`` times its end
        value).  Evaluated at the dof locations: the nodes, and the facet
        and edge dofs of quadratic elements.
    tractions
        ``{boundary: t}`` dead-load tractions at load factor 1: a vector,
        or a callable of the facet quadrature points ``x`` ``(d, nfacets,
        nqp)`` returning ``(d, nfacets, nqp)``, on FE and PG alike
        (:func:`skfem_pg.traction`).
    pressures
        ``{boundary: p}`` follower pressures at load factor 1, acting on
        the deformed surface (positive: against the outward normal): a
        number or a callable of the facets' reference midpoints ``(d,
        nfacets)``; on PG and linear FE
        (:class:`~skfem_pg.discretization.follower.FollowerPressure`),
        solved by Newton (serial).
    probes
        ``{label: point}`` where displacements are reported.
    steps
        Initial number of load steps.

    Examples
    --------
    A strip clamped at the left, pulled at the right, solved by PG and by
    Q1 on the same nodes:

    >>> import numpy as np, skfem as fem
    >>> from skfem_pg.materials import NeoHooke
    >>> mesh = fem.MeshQuad.init_tensor(np.linspace(0, 4, 9),
    ...                                 np.linspace(0, 1, 3))
    >>> mesh = mesh.with_boundaries({"left": lambda x: x[0] == 0,
    ...                              "right": lambda x: x[0] == 4})
    >>> sc = Scene("strip", mesh, NeoHooke(lam=60.0, mu=40.0),
    ...            clamped=["left"], tractions={"right": [1.0, 0.0]},
    ...            probes={"tip": (4.0, 1.0)})
    >>> pg_tip = sc.solve("PG", verbose=False).probes["tip"][0]
    >>> q1_tip = sc.solve("Q1", verbose=False).probes["tip"][0]
    >>> bool(abs(pg_tip / q1_tip - 1) < 0.02)
    True

    """

    def __init__(self, name: str, mesh: fem.Mesh, material,
                 clamped: Sequence[str] = (),
                 prescribed: dict | None = None,
                 tractions: dict | None = None,
                 probes: dict | None = None, steps: int = 1,
                 params: dict | None = None,
                 pressures: dict | None = None) -> None:
        self.name, self.mesh, self.material = name, mesh, material
        self.clamped = tuple(clamped)
        self.prescribed = prescribed or {}
        self.tractions = tractions or {}
        self.pressures = pressures or {}
        self.probes = {k: np.asarray(v, float)
                       for k, v in (probes or {}).items()}
        self.steps = steps
        self.params = params or {}
        self._check_boundaries()
        self._check_prescribed()

    def _check_prescribed(self):
        """``prescribed`` values: a callable ``f(x, t)`` or a dict of
        displacement components ``0 ... dim - 1`` to finite numbers (else
        ``ValueError`` naming the boundary, here rather than an
        ``IndexError`` at :meth:`solve`)."""
        d = self.dim
        for name, how in self.prescribed.items():
            if callable(how):
                continue
            if not isinstance(how, dict):
                raise ValueError(
                    "prescribed[{!r}] must be {{component: value}} or a "
                    "callable f(x, t), got {!r}".format(name, how))
            for c, val in how.items():
                if isinstance(c, bool) or not isinstance(
                        c, (int, np.integer)) or not 0 <= c < d:
                    raise ValueError(
                        "prescribed[{!r}] names component {!r}; a {}-D "
                        "displacement has components 0 ... {}".format(
                            name, c, d, d - 1))
                try:
                    ok = np.isfinite(float(val))
                except (TypeError, ValueError):
                    ok = False
                if not ok:
                    raise ValueError(
                        "prescribed[{!r}][{}] must be a finite number, got "
                        "{!r}".format(name, c, val))

    def _check_boundaries(self):
        """Every boundary the scene names exists on the mesh (else a
        ``ValueError`` with the names the mesh has, now rather than deep in
        scikit-fem at :meth:`solve`)."""
        named = list(self.clamped) + [k for k in self.prescribed
                                      if isinstance(k, str)] + [
            k for k in self.tractions if isinstance(k, str)] + list(
            self.pressures)
        have = sorted((self.mesh.boundaries or {}).keys())
        missing = sorted(set(named) - set(have))
        if missing:
            raise ValueError(
                "scene {!r} names the boundaries {} that its mesh does not "
                "have; the mesh has {} (name facets with "
                "mesh.with_boundaries({{'right': lambda x: x[0] == 1}}))"
                .format(self.name, ", ".join(map(repr, missing)),
                        ", ".join(map(repr, have)) if have else "none"))

    @property
    def dim(self):
        return self.mesh.dim()

    def key(self):
        """Text that identifies the problem apart from the mesh: name,
        material (type and every parameter at full precision),
        boundary conditions, loads, probes and parameters."""
        material = exact(self.material)
        return repr((self.name, material, exact(list(self.clamped)),
                     exact(self.prescribed),
                     exact({k: v if callable(v) else np.asarray(v, float)
                            for k, v in self.tractions.items()}),
                     exact(self.probes), exact(self.params),
                     exact(self.steps)) + ((exact({
                         k: v if callable(v) else float(v)
                         for k, v in self.pressures.items()}),)
                         if self.pressures else ()))

    def load_samples(self):
        """The values of every callable load at points where it acts: a
        traction ``t(x)`` at the vertices and centroid of each facet of its
        boundary, a prescribed ``f(x, t)`` there at load factors 1/4, 1/2
        and 1.  They join the :meth:`fingerprint`, so a function whose
        result changes (it reads a global, a file, ...) changes the key
        even when its code does not."""
        mesh = self.mesh
        out = []

        def points(name):
            f = np.asarray(mesh.boundaries[name]) if name in (
                mesh.boundaries or {}) else np.asarray(
                    mesh.normalize_facets(name))
            v = mesh.p[:, mesh.facets[:, f]]  # (d, vertices, facets)
            x = np.concatenate([v, v.mean(axis=1, keepdims=True)], axis=1)
            return np.ascontiguousarray(x.transpose(0, 2, 1))  # (d, nf, k)
        for name, t in sorted(self.tractions.items()):
            if callable(t):
                out.append((name, call_user(t, points(name),
                                            "the traction on {!r}"
                                            .format(name))))
        for name, p in sorted(self.pressures.items()):
            if callable(p):
                out.append((name, call_user(p, points(name).mean(axis=2),
                                            "the pressure on {!r}"
                                            .format(name))))
        for name, how in sorted(self.prescribed.items()):
            if callable(how):
                x = points(name).reshape(self.dim, -1)
                for lf in (0.25, 0.5, 1.0):
                    out.append((name, lf, call_user(
                        how, x, "the prescribed f(x, t) on {!r}".format(name),
                        lf)))
        return out

    def fingerprint(self, *extra):
        """SHA-1 of :meth:`key`, the mesh (vertices, elements and every
        named boundary's facets) and ``extra``: a reference solved for this
        fingerprint is valid for exactly this problem."""
        h = hashlib.sha1()
        h.update(self.key().encode())
        for sample in self.load_samples():
            h.update(repr(sample[:-1]).encode())
            h.update(np.ascontiguousarray(sample[-1]).tobytes())
        mesh = self.mesh
        h.update(type(mesh).__name__.encode())
        for a in (mesh.p, mesh.t):
            h.update(str(a.shape).encode())
            h.update(np.ascontiguousarray(a).tobytes())
        for kind in ("boundaries", "subdomains"):
            named = getattr(mesh, kind, None) or {}
            for name in sorted(named):
                h.update("{} {}".format(kind, name).encode())
                h.update(np.sort(np.asarray(named[name],
                                            dtype=np.int64)).tobytes())
        h.update(repr(extra).encode())
        return h.hexdigest()

    # -- bases ---------------------------------------------------------
    def fe_mesh(self, method, mesh=None):
        """The mesh a FE method runs on (triangles from quads, tets from
        hexes by splitting: the same nodes)."""
        mesh = self.mesh if mesh is None else mesh
        need = registry.fe_method(method).mesh
        if isinstance(mesh, need):
            return mesh
        if need is fem.MeshTri1 and isinstance(mesh, fem.MeshQuad1):
            return transfer_boundaries(mesh, mesh.to_meshtri())
        if need is fem.MeshTet1 and isinstance(mesh, fem.MeshHex1):
            return transfer_boundaries(mesh, mesh.to_meshtet())
        raise ValueError("{} needs a {} node set, the scene has a {}".format(
            method, need.__name__, type(mesh).__name__))

    def _dirichlet(self, basis):
        """Prescribed dofs ``D`` and their values as a function of the
        load factor, ``u_D(t)`` (a full-length vector)."""
        D, const, moving = [], np.zeros(basis.N), []
        claims = []  # (dofs, values at load factor 1, what prescribes)
        for name in self.clamped:
            D.append(basis.get_dofs(name).flatten())
            claims.append((D[-1], 0.0, "clamped {!r}".format(name)))
        d = self.dim
        for name, how in self.prescribed.items():
            dofs = basis.get_dofs(name)
            # every dof of a component: nodal, and the facet/edge dofs of
            # quadratic elements (a constant's or a function's interpolant)
            idx = [dofs.all("u^{}".format(c + 1)) for c in range(d)]
            if callable(how):
                D.extend(idx)
                moving.append((how, idx))
                continue
            for c, val in how.items():
                D.append(idx[c])
                const[idx[c]] = val
                claims.append((idx[c], float(val), "prescribed {!r} "
                               "component {}".format(name, c)))
        self._check_claims(basis, claims)
        D = np.unique(np.concatenate(D)) if D else np.zeros(0, int)
        locs = basis.doflocs

        def u_D(t):
            u = t * const
            for f, idx in moving:
                for c in range(d):
                    x = locs[:, idx[c]]
                    val = call_user(f, x, "the prescribed displacement "
                                    "f(x, t)", t)
                    if val.shape != x.shape:
                        raise ValueError(
                            "a prescribed displacement f(x, t) must return "
                            "shape (dim, n) = {} for x of that shape, got {}"
                            .format(x.shape, val.shape))
                    u[idx[c]] = val[c]
            return u
        return D, u_D

    @staticmethod
    def _check_claims(basis, claims):
        """A dof that two constant conditions prescribe with different
        values (a boundary both clamped and moved, or two boundaries that
        share nodes) raises ``ValueError`` naming both and the position:
        the one written last would win without a word."""
        if len(claims) < 2:
            return
        dofs = np.concatenate([np.asarray(c[0], dtype=np.int64)
                               for c in claims])
        vals = np.concatenate([np.full(len(c[0]), c[1]) for c in claims])
        who = np.concatenate([np.full(len(c[0]), i)
                              for i, c in enumerate(claims)])
        order = np.lexsort((vals, dofs))
        dofs, vals, who = dofs[order], vals[order], who[order]
        same = dofs[1:] == dofs[:-1]
        clash = np.flatnonzero(same & (vals[1:] != vals[:-1]))
        if len(clash):
            i = clash[0]
            x = basis.doflocs[:, dofs[i]]
            raise ValueError(
                "the scene prescribes dof {} (at {}) twice with different "
                "values: {} = {:g} and {} = {:g} ({} such dofs); give each "
                "boundary one condition (e.g. drop it from clamped=, or "
                "name the shared nodes' boundary once)".format(
                    dofs[i], np.round(x, 12).tolist(), claims[who[i]][2],
                    vals[i], claims[who[i + 1]][2], vals[i + 1],
                    len(np.unique(dofs[clash]))))

    def _weak_conditions(self):
        """The clamped and prescribed boundaries as
        :class:`~skfem_pg.formulations.WeakDirichlet` conditions."""
        out = {name: None for name in self.clamped}
        for name, how in self.prescribed.items():
            if callable(how):
                raise NotImplementedError(
                    "PG2 imposes Dirichlet conditions by Nitsche terms that "
                    "grow with the load factor; the prescribed f(x, t) on "
                    "{!r} is not a value times the load factor: prescribe "
                    "constant components ({{component: value}}) or use "
                    "'PG'".format(name))
            out[name] = dict(how)
        return out

    def _fe_traction(self, basis, mesh, name, t):
        what = "the traction t(x) on {!r}" if callable(t) \
            else "traction on {!r}"
        return fe_traction(basis, name, t, mesh=mesh, what=what.format(name))

    # -- solving -------------------------------------------------------
    def solve(self, scheme: str = "PG", mesh: fem.Mesh | None = None,
              verbose: bool | str = "auto", solver: str = "auto",
              tangent: str = "consistent", tol: float = 1e-9, comm=None,
              **basis_kwargs) -> Result:
        """Solve with a thesis name (``"VCBCPBG V5sn UnlP0"``, ``"PBG
        IUnlP0"``, :mod:`skfem_pg.naming`; ``basis_kwargs`` override its
        basis options), ``"PG"`` (the displacement formulation;
        ``basis_kwargs`` go to ``FamilyBasis``, e.g. ``method="PPG1"``),
        ``"PG2"`` (the blended quadratic basis; ``basis_kwargs``:
        ``families``, ``intorder``) or
        an FE comparator of :func:`skfem_pg.registry.fe_names` (also as
        ``"FEM Q1P0"``);
        ``tol``: Newton's relative residual tolerance
        (:func:`~skfem_pg.solvers.newton`); ``verbose``: its progress
        lines, ``True``, ``False`` or ``"auto"`` (from a few seconds on,
        :mod:`skfem_pg.progress`).  Returns a :class:`Result`.

        ``comm`` (an MPI communicator): solve on its ranks with
        :mod:`skfem_pg.distributed` (PG displacement formulations Unl/U1,
        PBG or PPG1; ``solver`` is then a PETSc options string).  Every
        rank gets the same :class:`Result`; its ``basis`` is the scikit-fem
        basis of the collocation mesh (the same numbering)."""
        if comm is not None:
            return self._solve_distributed(scheme, comm, verbose, tangent,
                                           tol, solver, basis_kwargs)
        setup = self.setup(scheme, mesh, tangent, **basis_kwargs)
        basis, model, t_pre = setup.basis, setup.model, setup.seconds
        x, hist = newton(setup.problem, steps=self.steps, solver=solver,
                         verbose=verbose, tol=tol)
        times = {"preprocess": t_pre,
                 "assemble": sum(h["t_assemble"] for h in hist),
                 "solve": sum(h["t_linear"] for h in hist)}
        u = x[:model.n_u]
        fields = model.fields(x)
        plastic = model.plastic_strain()
        if plastic is not None:  # per family (particle) or per cell
            fields["ep"] = plastic[0]
        f = external_load(setup.f_ext, model.n_u, model.n_u).vector(x)
        return Result(scheme, u, basis, self.evaluate(basis, u), times, hist,
                      fields=fields, model=model, x=x, f_ext=f)

    def _solve_distributed(self, scheme, comm, verbose, tangent, tol,
                           options, basis_kwargs):
        method, formulation, basis_kwargs = _scheme(scheme, basis_kwargs)
        if method == "PG2":
            raise NotImplementedError(
                "PG2 on MPI: the blended quadratic basis is serial; the "
                "distributed solver runs 'PG' and the thesis' names")
        if self.pressures:
            raise NotImplementedError(
                "follower pressures on MPI: the distributed Newton takes "
                "dead loads; solve scene {!r} serially".format(self.name))
        if method != "PG":
            raise NotImplementedError(
                "{} on MPI: FE methods run on scikit-fem's own distributed "
                "assembly (skfem.Dofs.decompose); the scene distributes PG"
                .format(scheme))
        if not registry.formulation(formulation).distributed \
                or frame_of(scheme) == "UL":
            raise NotImplementedError(
                "{} on MPI: the distributed Newton solves the formulations "
                "{} in the total Lagrangian frame".format(
                    scheme, ", ".join(registry.tokens(distributed=True))))
        t0 = time.perf_counter()
        part = distributed.Partition(self.mesh, comm)
        basis = part.basis(dim=self.dim, **basis_kwargs)
        model = model_for(formulation, basis, self.material, tangent)
        # the collocation mesh's FE basis: serial numbering, FE-consistent
        # loads (those of PG without boundary variants), Dirichlet dofs
        serial = fem.Basis(self.mesh, fem.ElementVector(
            linear_elements(self.mesh)[0]))
        f = sum((self._fe_traction(serial, self.mesh, n, t)
                 for n, t in self.tractions.items()), np.zeros(serial.N))
        D, u_D = self._dirichlet(serial)
        t_pre = time.perf_counter() - t0
        u, hist = distributed.newton(
            model, part, f, D=D, u_D=u_D, steps=self.steps, tol=tol,
            options=None if options == "auto" else options, verbose=verbose)
        times = {"preprocess": t_pre,
                 "assemble": sum(h["t_assemble"] for h in hist),
                 "solve": sum(h["t_linear"] for h in hist)}
        return DistributedResult(
            scheme, u, serial, self.evaluate(serial, u, part.particles),
            times, hist, model=model, x=u, f_ext=f, partition=part)

    def setup(self, scheme="PG", mesh=None, tangent="consistent",
              **basis_kwargs):
        """What :meth:`solve` hands Newton's method for ``scheme`` (as in
        :meth:`solve`): a :class:`Setup` ``(basis, model, f_ext, D, u_D,
        seconds)`` whose ``problem`` is the
        :class:`~skfem_pg.solvers.problem.Problem`; ``u_D(t)`` gives the
        prescribed values at load factor ``t``.  A
        name in the updated Lagrangian frame (``"... Unl UL"``) gives an
        :class:`~skfem_pg.formulations.UpdatedLagrange` model, rebuilt
        every ``params["ul_every"]`` converged steps (default 1)."""
        t0 = time.perf_counter()
        method, formulation, basis_kwargs = _scheme(scheme, basis_kwargs)
        if method == "PG":
            mesh = self.mesh if mesh is None else mesh
            basis = FamilyBasis(Particles.from_mesh(mesh), dim=self.dim,
                                **basis_kwargs)
            if frame_of(scheme) == "UL":
                every = self.params.get("ul_every", 1)
                build_ul = registry.formulation(formulation).build_ul
                model = (UpdatedLagrange(basis, self.material, every=every)
                         if build_ul is None
                         else build_ul(basis, self.material, every))
            else:
                model = model_for(formulation, basis, self.material, tangent)
            f = sum((pg_traction(basis, n, t)
                     for n, t in self.tractions.items()), np.zeros(basis.N))
        elif method == "PG2":
            if self.pressures:
                raise NotImplementedError(
                    "follower pressures on the blended quadratic basis "
                    "(PG2): they act on PG and linear FE")
            mesh = self.mesh if mesh is None else mesh
            basis = BlendBasis(Particles.from_mesh(mesh), dim=self.dim,
                               **basis_kwargs)
            self._dirichlet(basis)  # the same checks of the conditions
            model = WeakDirichlet(model_for("Unl", basis, self.material,
                                            tangent),
                                  self._weak_conditions())
            f = sum((pg_traction(basis, n, t)
                     for n, t in self.tractions.items()),
                    model.load())
            return Setup(basis, model, f, np.zeros(0, dtype=np.int64), None,
                         time.perf_counter() - t0)
        elif method in registry.fe_names():
            if basis_kwargs:
                raise ValueError(
                    "{} is a scikit-fem element: the family basis options "
                    "{} do not apply to it".format(
                        method, ", ".join(sorted(basis_kwargs))))
            mesh = self.fe_mesh(method, mesh)
            fe = registry.fe_method(method)
            basis = fem.Basis(mesh, fem.ElementVector(fe.element()),
                              intorder=fe.intorder)
            model = model_for(method, basis, self.material)
            f = sum((self._fe_traction(basis, mesh, n, t)
                     for n, t in self.tractions.items()), np.zeros(basis.N))
        else:
            raise ValueError("unknown method {!r}: 'PG' or one of {}".format(
                method, ", ".join(registry.fe_names())))
        D, u_D = self._dirichlet(basis)
        if self.pressures:  # the dead load beside the follower loads
            f = [f] + [FollowerPressure(basis, name, p)
                       for name, p in sorted(self.pressures.items())]
        return Setup(basis, model, f, D, u_D, time.perf_counter() - t0)

    def evaluate(self, basis, u, particles=None):
        """Displacements at the probe points: at the particle there for
        a family basis (or given ``particles``), else interpolated."""
        out = {}
        d = self.dim
        if particles is None and isinstance(basis, (FamilyBasis,
                                                    BlendBasis)):
            particles = basis.particles  # Kronecker at the particles
        for label, x in self.probes.items():
            if particles is not None:
                try:
                    i = point_index(particles.x, x, "particle")
                except ValueError as err:
                    raise ValueError("probe {} at {} is not a particle ({})"
                                     .format(label, tuple(map(float, x)),
                                             err)) from None
                out[label] = u.reshape(-1, d)[i].copy()
            else:
                xi = inside(basis.mesh, x[:, None])
                out[label] = (basis.probes(xi) @ u).reshape(d)
        return out


def _scheme(scheme, basis_kwargs):
    """``(method, formulation, basis_kwargs)`` of a scene method name:
    ``method`` is an FE comparator (:mod:`skfem_pg.registry`), ``"PG2"``
    or ``"PG"`` (for ``"PG"`` and thesis names, whose basis options are
    merged under the given ``basis_kwargs``)."""
    method = fe_method(scheme) or scheme
    if method in registry.fe_names() or method in ("PG", "PG2"):
        return method, "Unl", basis_kwargs
    try:  # a thesis name, e.g. "VCBCPBG V5sn Unl TL"
        kw, _ = parse(method)
    except ValueError as err:
        raise ValueError("unknown method {!r}: 'PG', a thesis name (e.g. "
                         "'VCPBG Unl') or one of {} ({})".format(
                             method, ", ".join(registry.fe_names()),
                             err)) from None
    return "PG", formulation_of(method), {**kw, **basis_kwargs}


class Setup(NamedTuple):
    """What :meth:`Scene.setup` returns; unpacks as ``basis, model, f_ext,
    D, u_D, seconds`` (``seconds``: the time spent making them).
    ``f_ext`` is the dead load vector, or with ``pressures`` the list of
    it and the follower loads, which :func:`~skfem_pg.solvers.newton`
    takes as it is.

    Examples
    --------
    >>> import numpy as np, skfem as fem
    >>> from skfem_pg.materials import NeoHooke
    >>> mesh = fem.MeshQuad().refined(2).with_boundaries(
    ...     {"left": lambda x: x[0] == 0})
    >>> setup = Scene("block", mesh, NeoHooke(lam=60.0, mu=40.0),
    ...               clamped=["left"]).setup("PG")
    >>> basis, model, f_ext, D, u_D, seconds = setup  # unpacks as before
    >>> setup.problem.model is model, len(setup.D)
    (True, 10)

    """

    basis: Any
    model: Any
    f_ext: np.ndarray
    D: np.ndarray
    u_D: Any
    seconds: float

    @property
    def problem(self):
        """The :class:`~skfem_pg.solvers.problem.Problem` the drivers
        take."""
        return Problem(self.model, f_ext=self.f_ext, D=self.D, u_D=self.u_D)


def centroid_tree(mesh):
    """KD-tree of the element centroids (for :func:`inside`)."""
    from scipy.spatial import cKDTree
    return cKDTree(mesh.p[:, mesh.t].mean(axis=1).T)


def inside(mesh, x, tree=None):
    """Points ``x`` (``(d, n)``) moved by 1e-8 of their distance towards
    the nearest element centroid, so that points on the boundary (a probe
    on a hole, a boundary point of another discretisation of the same
    straight-sided domain) fall inside ``mesh`` for its element finder.
    ``tree``: a cached :func:`centroid_tree` of ``mesh``."""
    tree = centroid_tree(mesh) if tree is None else tree
    x = np.asarray(x, float)
    _, i = tree.query(x.T)
    return x + 1e-8 * (tree.data[i].T - x)
