"""Checkpoints (issue #28): atomic writes, a fingerprint that refuses
another model, and resumed runs — static (adaptive steps), Newmark and
central differences — that end where the uninterrupted run ends."""
import os

import numpy as np
import pytest
import skfem as fem

import skfem_pg as pg
from skfem_pg.formulations import model_for
from skfem_pg.materials import J2Plasticity, NeoHookeIsoVol
from skfem_pg.solvers import (central_difference, checkpoint, lumped_mass,
                              newmark, newton)

STEEL = J2Plasticity.from_young(206.9, 0.29, 0.45, H=0.13, sigma_yinf=1.165,
                                delta=16.93)


def strip(nx=8, ny=2):
    return fem.MeshQuad.init_tensor(
        np.linspace(0, 4, nx + 1), np.linspace(0, 1, ny + 1)
    ).with_boundaries({"left": lambda x: x[0] == 0,
                       "right": lambda x: x[0] == 4})


class Stop(Exception):
    pass


def stop_after(n):
    """A callback that kills the run after ``n`` converged steps."""
    count = [0]

    def callback(*args):
        count[0] += 1
        if count[0] == n:
            raise Stop
    return callback


def test_an_adaptive_plastic_run_resumes_to_round_off(tmp_path):
    mesh = strip()
    basis = pg.FamilyBasis(mesh, dim=2)
    D = basis.get_dofs(["left", "right"]).all()
    uD = np.zeros(basis.N)
    uD[basis.get_dofs("right").all("u^1")] = 0.12
    kw = dict(D=D, u_D=uD, steps=8, verbose=False)
    full = model_for("Unl", basis, STEEL)
    x_full, hist_full = newton(full, None, **kw)
    ck = str(tmp_path / "run")  # no suffix: ".npz" is added
    part = model_for("Unl", basis, STEEL)
    with pytest.raises(Stop):
        newton(part, None, checkpoint=ck, callback=stop_after(3), **kw)
    resumed = model_for("Unl", basis, STEEL)
    x, hist = newton(resumed, None, resume=ck, **kw)
    assert len(hist) == len(hist_full) - 3  # the same steps after it
    assert np.abs(x - x_full).max() <= 1e-12 * np.abs(x_full).max()
    assert np.abs(resumed.history.alpha() - full.history.alpha()).max() \
        <= 1e-12


def test_a_checkpoint_of_another_model_is_refused_by_name(tmp_path):
    mesh = strip()
    basis = pg.FamilyBasis(mesh, dim=2)
    x = np.zeros(basis.N)
    path = checkpoint.save(tmp_path / "a", model_for("Unl", basis, STEEL),
                           x, 0.5)
    assert path.endswith("a.npz")
    other = J2Plasticity.from_young(206.9, 0.29, 0.45, H=0.2)
    cases = [
        (model_for("UnlP0", basis, STEEL), "formulation"),
        (model_for("Unl", basis, other), "material"),
        (model_for("Unl", pg.FamilyBasis(mesh, dim=2, vc_boundary="p"),
                   STEEL), "basis"),
        (model_for("Unl", pg.FamilyBasis(mesh.translated((1.0, 0.0)),
                                         dim=2), STEEL), "positions"),
        (model_for("Unl", pg.FamilyBasis(strip(9), dim=2), STEEL),
         "unknowns")]
    for model, field in cases:
        with pytest.raises(ValueError, match="another model — " + field):
            checkpoint.load(tmp_path / "a", model)
    x0, lam = checkpoint.load(tmp_path / "a.npz",
                              model_for("Unl", basis, STEEL))
    assert lam == 0.5 and np.array_equal(x0, x)


def test_a_failed_write_keeps_the_previous_checkpoint(tmp_path, monkeypatch):
    basis = pg.FamilyBasis(strip(), dim=2)
    model = model_for("Unl", basis, STEEL)
    checkpoint.save(tmp_path / "c", model, np.ones(basis.N), 0.25)

    def killed(fh, **arrays):
        fh.write(b"PK\x03\x04 half a zip")
        raise KeyboardInterrupt
    monkeypatch.setattr(np, "savez", killed)
    with pytest.raises(KeyboardInterrupt):
        checkpoint.save(tmp_path / "c", model, np.zeros(basis.N), 0.5)
    monkeypatch.undo()
    x, lam = checkpoint.load(tmp_path / "c", model)
    assert lam == 0.25 and np.all(x == 1.0)
    assert os.listdir(tmp_path) == ["c.npz"]  # no temporary left
    (tmp_path / "d.npz").write_bytes(b"PK\x03\x04 truncated")
    with pytest.raises(ValueError, match="d.npz cannot be read"):
        checkpoint.load(tmp_path / "d", model)


def _bar():
    mesh = strip(10, 2)
    basis = pg.FamilyBasis(mesh, dim=2)
    D = basis.get_dofs("left").all()
    v0 = np.zeros(basis.N)
    v0[0::2] = 0.05 * basis.doflocs[0, 0::2]
    return basis, D, v0


@pytest.mark.parametrize("integrator", ["newmark", "central"])
def test_a_dynamic_run_resumes_to_round_off(tmp_path, integrator):
    basis, D, v0 = _bar()
    material = NeoHookeIsoVol(mu=40.0, K=80.0)
    m = lumped_mass(basis, 1.0)

    def run(**kw):
        model = model_for("Unl", basis, material)
        if integrator == "newmark":
            return newmark(model, m, 0.6, 0.02, D=D, v0=v0, verbose=False,
                           **kw)
        return central_difference(model, m, 0.6, D=D, v0=v0, verbose=False,
                                  **kw)
    full = run()
    ck = checkpoint.Every(tmp_path / "dyn", steps=5)
    with pytest.raises(Stop):  # at step 11; the checkpoint of step 10
        run(checkpoint=ck, callback=stop_after(12))
    assert os.path.exists(tmp_path / "dyn.npz")
    resumed = run(resume=tmp_path / "dyn")
    assert resumed.steps == full.steps and resumed.t == full.t
    for a, b in ((resumed.x, full.x), (resumed.v, full.v)):
        assert np.abs(a - b).max() <= 1e-12 * np.abs(b).max()
    e_full, e = full.series("relative_error"), resumed.series(
        "relative_error")
    assert len(e) == len(e_full) and np.abs(e - e_full).max() <= 1e-12


def test_a_checkpoint_knows_its_driver_and_what_it_holds(tmp_path):
    """Issue 47: a checkpoint carries the kind of run that wrote it — an
    explicit run's is refused by newton (it was read as load factor t and
    returned after 0 steps), a static one by the integrators (a bare
    KeyError) — and save checks what it writes (a load factor of 1.5 or
    NaN, the wrong length); a plain .npz and an older format are named
    as such."""
    basis, D, v0 = _bar()
    material = NeoHookeIsoVol(mu=40.0, K=80.0)
    m = lumped_mass(basis, 1.0)
    model = model_for("Unl", basis, material)
    ck = checkpoint.Every(tmp_path / "dyn", steps=5)
    central_difference(model, m, 0.3, D=D, v0=v0, verbose=False,
                       checkpoint=ck)
    with pytest.raises(ValueError, match="explicit run .*newton.* cannot "
                                         "resume"):
        newton(model_for("Unl", basis, material), D=D, resume=ck.path)
    with pytest.raises(ValueError, match="explicit run .*Newmark run "
                                         "cannot"):
        newmark(model_for("Unl", basis, material), m, 0.6, 0.02, D=D,
                verbose=False, resume=ck.path)
    static = checkpoint.save(tmp_path / "s", model, np.zeros(basis.N), 0.5,
                             kind="static")
    with pytest.raises(ValueError, match="static run .*explicit run"):
        central_difference(model_for("Unl", basis, material), m, 0.6, D=D,
                           verbose=False, resume=static)
    # a checkpoint of no driver lacks the integrator's state: named
    bare = checkpoint.save(tmp_path / "b", model, np.zeros(basis.N), 0.1)
    with pytest.raises(ValueError, match=r"lacks the state .*\(v, a, "):
        central_difference(model_for("Unl", basis, material), m, 0.6, D=D,
                           verbose=False, resume=bare)
    # save checks what it writes
    for load, kind in ((1.5, "static"), (np.nan, None), (-1.0, "explicit")):
        with pytest.raises(ValueError, match="load = "):
            checkpoint.save(tmp_path / "x", model, np.zeros(basis.N), load,
                            kind=kind)
    with pytest.raises(ValueError, match="shape .* unknowns"):
        checkpoint.save(tmp_path / "x", model, np.zeros(basis.N + 2), 0.5)
    with pytest.raises(ValueError, match="non-finite"):
        checkpoint.save(tmp_path / "x", model, np.full(basis.N, np.inf))
    with pytest.raises(ValueError, match="kind must be"):
        checkpoint.save(tmp_path / "x", model, np.zeros(basis.N), kind="ul")
    # a load factor outside [0, 1] in a checkpoint of no driver: newton
    # refuses it instead of returning the stored x after 0 steps
    odd = checkpoint.save(tmp_path / "o", model, np.zeros(basis.N), 1.5)
    with pytest.raises(ValueError, match=r"load factor 1.5.*\[0, 1\]"):
        newton(model_for("Unl", basis, material), D=D, resume=odd)
    np.savez(tmp_path / "results.npz", u=np.zeros(basis.N))
    with pytest.raises(ValueError, match="not a skfem-pg checkpoint .*u"):
        checkpoint.load(tmp_path / "results", model)
    with np.load(static) as f:
        old = {k: f[k] for k in f.files}
    old["format"] = 2
    np.savez(tmp_path / "old.npz", **old)
    with pytest.raises(ValueError, match="format 2 .*earlier"):
        checkpoint.load(tmp_path / "old", model)


def test_a_checkpoint_of_another_triangulation_is_refused(tmp_path):
    """Issue 47: the same vertices triangulated otherwise (same counts)
    differ in the fingerprint's cells — a crack mask or a history would
    land on other cells."""
    quads = fem.MeshQuad.init_tensor(np.linspace(0, 1, 4),
                                     np.linspace(0, 1, 4))
    q = quads.t
    a = fem.MeshTri(quads.p, np.hstack([q[[0, 1, 2]], q[[0, 2, 3]]]))
    b = fem.MeshTri(quads.p, np.hstack([q[[0, 1, 3]], q[[1, 2, 3]]]))
    material = NeoHookeIsoVol(mu=40.0, K=80.0)
    ma = model_for("Unl", pg.FamilyBasis(a, dim=2), material)
    mb = model_for("Unl", pg.FamilyBasis(b, dim=2), material)
    path = checkpoint.save(tmp_path / "a", ma, np.zeros(ma.N), 0.5)
    with pytest.raises(ValueError, match="cells"):
        checkpoint.load(path, mb)
    assert checkpoint.load(path, ma)[1] == 0.5
