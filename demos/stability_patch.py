"""Stability of a free, randomly discretized patch (Ganzenmüller,
Hiermaier & May, Figs. 2–3).

A square patch (E = 1, nu = 0.3, rho = 1, neo-Hooke) discretized by the
centroids of about 450 irregular gmsh quadrilaterals (volumes = quad
areas), families of the 12 nearest particles (pairwise completed).  Every
particle is displaced by a 10 % isotropic stretch and released; explicit
central differences (leap-frog, diagonal mass, CFL time step) integrate
ten periods of the breathing mode.  Compared: U1 (WTE1: classical
correspondence = first-order corrected TL-SPH, constant F per family) and
VC PBG Unl (MTE1 + BC + V5).

Prints the static view — eigenvalues of the free tangent below half of
Unl's first deformation mode (spurious soft modes) — and the dynamic one:
the particle disorder — the particle-scale roughness of the displacement,
its difference to the MLS1 average of the family (zero for linear, O(h²)
for smooth fields), relative to the initial stretch — at the end of each
breathing period, and the energy drift.  Writes
out/stability_patch.png (snapshots, disorder vs time)
and VTUs of the final states.

    python demos/stability_patch.py [--periods 10] [--size 0.11]
"""
import os

import numpy as np
import scipy.sparse.linalg as spl

import skfem_pg as pg
from harness import demo_parser, output_dir
from harness import save_figure
from skfem_pg import materials as mat
from skfem_pg.formulations import Hyperelastic
from skfem_pg.materials import lame
from skfem_pg.discretization.shape import mls1_master_values
from skfem_pg.analysis.spectrum import classify, free_modes

OUT = output_dir(create=False)  # --out, $SKFEM_PG_OUT or ./out
FORMULATIONS = {"U1 (WTE1)": dict(shape="WTE1"), "VC PBG Unl": dict()}


def patch(size):
    mesh = pg.meshing.from_geo(pg.meshing.geo_path("square.geo"), size=size,
                               recombine=True)
    p = pg.Particles.from_mesh(mesh, kind="centroids")
    return mesh, p, pg.families.nearest(p, 12, pairwise=True)


def roughness(smoother, mem, V, u, scale):
    """Particle-scale noise of ``u``: its difference to the MLS1 average
    of the family members (zero for linear fields, O(h²) for smooth ones),
    ``|u - S u|_V / scale``."""
    U = u.reshape(-1, 2)
    r = U - np.einsum("km,kma->ka", smoother, U[mem])
    return float(np.sqrt(np.sum(V[:, None] * r ** 2)) / scale)


def simulate(basis, material, stretch, periods, record=8):
    """Leap-frog from the stretched state at rest; returns times,
    disorder, energy, snapshots."""
    model = Hyperelastic(basis, material)
    x, V = basis.particles.x, basis.particles.volumes
    mem, _ = basis.families.padded()
    smoother = mls1_master_values(x, V, basis.families)
    M = np.repeat(V, 2)  # rho = 1
    xc = x - (V * x).sum(1, keepdims=True) / V.sum()
    u = (stretch * xc).T.ravel()
    K = model.tangent(model.state(np.zeros_like(u)))
    Dm = 1.0 / np.sqrt(M)
    Kn = K.multiply(Dm[:, None]).multiply(Dm[None, :]).tocsr()
    lmax = spl.eigsh(Kn, k=1, which="LA", return_eigenvectors=False)[0]
    dt = 0.4 * 2.0 / np.sqrt(lmax)  # CFL with margin for the stretch
    # breathing frequency from the Rayleigh quotient of the affine mode
    a = xc.T.ravel()
    omega = np.sqrt((a @ (K @ a)) / (a @ (M * a)))
    period = 2 * np.pi / omega
    n_steps = int(np.ceil(periods * period / dt))
    scale = float(np.sqrt(np.sum(V * (stretch * xc) ** 2)))
    v = np.zeros_like(u)
    f = model.internal_force(model.state(u))
    W0 = None
    out = {"t": [], "disorder": [], "energy": [], "snapshots": [],
           "dt": dt, "period": period, "steps": n_steps}
    every = max(1, n_steps // 400)
    snap_at = set(np.linspace(0, n_steps, record).astype(int))
    for step in range(n_steps + 1):
        if step % every == 0 or step in snap_at:
            st = model.state(u)
            W = model.energy(st)
            E = W + 0.5 * float(v @ (M * v))
            W0 = E if W0 is None else W0
            out["t"].append(step * dt)
            out["disorder"].append(roughness(smoother, mem, V, u, scale))
            out["energy"].append(E / W0 - 1.0)
            if step in snap_at:
                out["snapshots"].append((step * dt, u.copy()))
        if step == n_steps:
            break
        v -= 0.5 * dt * f / M
        u += dt * v
        state = model.state(u)
        if model.min_J(state) <= 0:
            out["failed"] = step * dt
            break
        f = model.internal_force(state)
        v -= 0.5 * dt * f / M
    out["u"] = u
    return out


def main(periods=10, size=0.11):
    mesh, p, fam = patch(size)
    lam, mu = lame(1.0, 0.3)
    material = mat.NeoHooke(lam=lam, mu=mu)
    print("free patch: {} centroid particles, families {}..{} members, "
          "10 % isotropic stretch, {} breathing periods".format(
              p.n, fam.sizes.min(), fam.sizes.max(), periods))
    bases = {name: pg.FamilyBasis(p, fam, dim=2, **kw)
             for name, kw in FORMULATIONS.items()}
    M = np.repeat(p.volumes, 2)
    spectra = {}
    for name, b in bases.items():
        model = Hyperelastic(b, material)
        spectra[name] = free_modes(model.tangent(model.state(np.zeros(b.N))),
                                   M)
    ref = spectra["VC PBG Unl"]["eigenvalues"][3]
    print("\nstatic view: eigenvalues of the free tangent (M = diag V)")
    for name, s in spectra.items():
        c = classify(s["eigenvalues"], s["scale"], 3, ref)
        print("  {:12s} zero {:2d}, soft (< {:.3g}) {:3d}, first "
              "deformation {:.3e}".format(name, c["zero"], 0.5 * ref,
                                          c["soft"], c["first_deformation"]))
    runs = {}
    print("\ndynamic view: disorder = |u - MLS1 average of u| / "
          "|initial stretch|")
    for name, b in bases.items():
        r = simulate(b, material, 0.1, periods)
        runs[name] = r
        t = np.array(r["t"])
        d = np.array(r["disorder"])
        ends = [d[np.searchsorted(t, k * r["period"]) - 1]
                for k in range(1, periods + 1)
                if k * r["period"] <= t[-1] + 1e-12]
        print("  {:12s} dt {:.3g}, period {:.3g}, {} steps{}".format(
            name, r["dt"], r["period"], r["steps"],
            ", FAILED (J <= 0) at t = {:.3g}".format(r["failed"])
            if "failed" in r else ""))
        print("    disorder after each period: " + " ".join(
            "{:.2e}".format(v) for v in ends))
        print("    energy drift max |E/E0 - 1| = {:.2e}".format(
            np.abs(r["energy"]).max()))
    plot(p, runs, os.path.join(OUT, "stability_patch.png"))
    for name, r in runs.items():
        fn = os.path.join(OUT, "stability_patch_{}.vtu".format(
            name.split()[0].lower()))
        pg.write_vtu(fn, p, u=r["u"].reshape(-1, 2))
    return spectra, runs


def plot(p, runs, fn):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    os.makedirs(OUT, exist_ok=True)
    names = list(runs)
    fig, axes = plt.subplots(len(names), 4, figsize=(14, 7))
    for row, name in enumerate(names):
        snaps = runs[name]["snapshots"]
        picks = [snaps[0], snaps[len(snaps) // 2], snaps[-1]]
        for col, (t, u) in enumerate(picks):
            ax = axes[row, col]
            xd = p.x + u.reshape(-1, 2).T
            ax.scatter(*xd, s=4)
            ax.set_aspect("equal")
            ax.set_title("{}: t = {:.1f}".format(name, t), fontsize=9)
        ax = axes[row, 3]
        ax.semilogy(runs[name]["t"], np.maximum(runs[name]["disorder"],
                                                1e-16))
        ax.set_xlabel("t")
        ax.set_ylabel("disorder")
    save_figure(fig, fn)


if __name__ == "__main__":
    ap = demo_parser(__doc__)
    ap.add_argument("--periods", type=int, default=10,
                    help='breathing-mode periods integrated')
    ap.add_argument("--size", type=float, default=0.11,
                    help='gmsh element size of the quadrilaterals whose centroids are the particles')
    a = ap.parse_args()
    OUT = output_dir(a.out)
    main(*((1, 0.3) if a.quick else (a.periods, a.size)))
