"""Eigenmodes of the free, unloaded block (thesis 7.2.1, Fig. 7.6).

A free 20 x 10 particle block (2 x 1, E = 1, nu = 0.4, linear elasticity),
lumped mass M = diag(V): the generalized spectrum K phi = lambda M phi of
U1 (WTE1: classical correspondence, FE-connectivity families and a 3.01 h
horizon), PBG Unl (MTE1) without and with VC, PBG Unl with a 3.01 h
horizon, PPG Unl, the stabilized under-integrated U1SUnl and U1SIG (thesis
6.3; the neo-Hooke tangent at rest, which is this linear elasticity) and FE
Q1 on the same nodes.  Prints, per formulation,
the number of zero eigenvalues (3 = rigid-body modes only), the number of
soft modes below half of Q1's first deformation mode, and the first
deformation eigenvalue; plots the lowest 40 eigenvalues and the first
deformation mode of U1 and of VC PBG Unl (out/eigenmodes.png).

    python demos/eigenmodes.py [--nx 20 --ny 10] [--distortion 0.0]
"""
import os

import numpy as np
import skfem as fem

import skfem_pg as pg
from harness import demo_parser, output_dir
from harness import save_figure
from skfem_pg.materials import lame
from skfem_pg.formulations import U1SIG, U1SUnl, linear_elasticity
from skfem_pg.analysis.spectrum import classify, free_modes

OUT = output_dir(create=False)  # --out, $SKFEM_PG_OUT or ./out


def formulations(p):
    h301 = pg.families.horizon(p, factor=3.01)
    return {
        "U1 (WTE1)": dict(shape="WTE1"),
        "U1, δ = 3.01h": dict(shape="WTE1", families=h301),
        "PBG Unl": dict(vc=None),
        "VC PBG Unl": dict(),
        "VC PBG Unl, δ = 3.01h": dict(families=h301),
        "VC PPG Unl": dict(method="PPG1"),
    }


def main(nx=20, ny=10, distortion=0.0):
    mesh = fem.MeshQuad.init_tensor(np.linspace(0, 2, nx + 1),
                                    np.linspace(0, 1, ny + 1))
    if distortion:
        mesh = pg.meshing.distort(mesh, distortion, seed=1)
    p = pg.Particles.from_mesh(mesh)
    M = np.repeat(p.volumes, 2)
    form = linear_elasticity(*lame(1.0, 0.4))
    q1 = fem.Basis(mesh, fem.ElementVector(fem.ElementQuad1()), intorder=2)
    spectra = {"FE Q1": free_modes(pg.assemble(form, q1), M, vectors=True)}
    for name, kw in formulations(p).items():
        b = pg.FamilyBasis(p, dim=2, **kw)
        spectra[name] = free_modes(pg.assemble(form, b), M, vectors=True)
    unl = pg.FamilyBasis(p, dim=2)
    material = pg.materials.NeoHookeIsoVol.from_lame(*lame(1.0, 0.4))
    for name, cls in (("VC PBG U1SUnl", U1SUnl), ("VC PBG U1SIG", U1SIG)):
        model = cls(unl, material)
        K = model.tangent(model.state(model.initial()))
        spectra[name] = free_modes(K, M, vectors=True)
    ref = spectra["FE Q1"]["eigenvalues"][3]
    print("free {} x {} block, nu = 0.4, K phi = lambda M phi; Q1's first "
          "deformation mode lambda_4 = {:.4e}".format(nx, ny, ref))
    print("{:24s} {:>5s} {:>9s} {:>6s} {:>12s}".format(
        "formulation", "zero", "spurious", "soft", "lambda_4"))
    for name, s in spectra.items():
        c = classify(s["eigenvalues"], s["scale"], 3, ref)
        print("{:24s} {:5d} {:9d} {:6d} {:12.4e}".format(
            name, c["zero"], c["spurious_zero"], c["soft"],
            c["first_deformation"]))
    print("(thesis Fig. 7.6: U1 shows near-zero spurious modes, Unl and "
          "PPG Unl exactly 3 zeros)")
    plot(mesh, spectra, os.path.join(OUT, "eigenmodes.png"))
    return spectra


def plot(mesh, spectra, fn):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig = plt.figure(figsize=(12, 4.5))
    ax = fig.add_subplot(1, 3, 1)
    for name, s in spectra.items():
        lam = np.maximum(s["eigenvalues"][:40], 1e-16)
        ax.semilogy(np.arange(1, len(lam) + 1), lam, ".-", label=name)
    ax.set_xlabel("mode")
    ax.set_ylabel("eigenvalue λ")
    ax.legend(fontsize=7)
    ax.set_title("lowest 40 eigenvalues")
    for i, name in enumerate(["U1 (WTE1)", "VC PBG Unl"]):
        ax = fig.add_subplot(1, 3, 2 + i)
        v = spectra[name]["vectors"][:, 3].reshape(-1, 2).T
        v = 0.15 * v / np.abs(v).max()
        ax.scatter(*(mesh.p + v), s=6)
        ax.set_aspect("equal")
        ax.set_title("{}: mode 4".format(name))
    save_figure(fig, fn)


if __name__ == "__main__":
    ap = demo_parser(__doc__)
    ap.add_argument("--nx", type=int, default=20,
                    help='elements along the 2 x 1 block')
    ap.add_argument("--ny", type=int, default=10,
                    help='elements across the 2 x 1 block')
    ap.add_argument("--distortion", type=float, default=0.0,
                    help='random interior node distortion, in element sizes')
    a = ap.parse_args()
    OUT = output_dir(a.out)
    main(*((6, 3) if a.quick else (a.nx, a.ny)), a.distortion)
