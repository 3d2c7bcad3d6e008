r"""
Near incompressibility: formulations by name on one scene
=========================================================

Cook's membrane (48 × 44/16 × 60, clamped on the left, a shear traction of
total force 1 on the right) of a nearly incompressible neo-Hooke material
(:math:`\mu = 0.375`, :math:`K = 10^4 \mu`, plane strain).  A
:class:`~skfem_pg.scenes.Scene` holds the problem once; ``scene.solve``
runs any Table 7.1 name on particles collocated from the mesh, or a
scikit-fem element on the same mesh: the displacement formulation (locks),
its mean-dilatation variant UnlP0, and Q1 and Q1P0 for comparison.
``reference.overkill`` solves the scene with Q2 on the mesh refined twice
(about a minute the first time, then cached in ``~/.cache/skfem_pg``;
refined once it differs by 0.56 %).

The number it shows: the error of the corner's vertical displacement at
16 × 16 cells.  Displacement-only Unl and Q1 lock (−64.5 % and −61.0 %);
UnlP0 and Q1P0 do not (−3.6 % and −0.6 %: here the practitioner's Q1P0 is
the more accurate).
"""
import os

import skfem_pg as pg
from skfem_pg import materials
from skfem_pg.scenes import Scene
from skfem_pg.scenes.reference import overkill

MU = 0.375
material = materials.NeoHookeIsoVol(mu=MU, K=1e4 * MU)
mesh = pg.meshing.cook_membrane(16, kind="quad")
scene = Scene("cook-incompressible-ex04", mesh, material, clamped=["left"],
              tractions={"right": [0.0, 1.0 / 16]}, probes={"A": (48, 60)},
              steps=2)
v_ref = overkill(scene, refine=2, verbose=False).probes["A"][1]

errors = {}
for name in ("VCBCPBG V5m Unl", "VCBCPBG V5m UnlP0", "FEM Q1", "FEM Q1P0"):
    result = scene.solve(name)
    errors[name] = result.probes["A"][1] / v_ref - 1
    print("{:20s} v_A = {:.4f} ({:+.1%}), {:.2f} s".format(
        name, result.probes["A"][1], errors[name], result.total_time))

if __name__ == "__main__":
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(5.5, 3))
    ax.barh(list(errors), [100 * e for e in errors.values()], color="C0")
    ax.axvline(0, color="k", lw=0.8)
    ax.set_xlabel("error of v_A against the Q2 overkill [%]")
    out = os.environ.get("SKFEM_PG_OUT", "out")
    os.makedirs(out, exist_ok=True)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "ex04_incompressible.png"), dpi=120)
