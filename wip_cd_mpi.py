import sys, numpy as np, skfem as fem, skfem_pg as pg
from mpi4py import MPI
from skfem_pg import distributed as dist
from skfem_pg.formulations import Hyperelastic
from skfem_pg.materials import NeoHooke, lame
from skfem_pg.solvers import RigidWall
comm = MPI.COMM_WORLD
kind = sys.argv[1] if len(sys.argv) > 1 else "pg"
mesh = fem.MeshQuad.init_tensor(np.linspace(0, 1, 13), np.linspace(0, 2, 25))
mat = NeoHooke(*lame(1000.0, 0.3))
rho = 1.0
def v0_of(x):
    v = np.zeros_like(x); v[1] = -1.0 - 0.3 * x[0]; v[0] = 0.2 * x[1]
    return v.T.ravel()
if kind == "pg":
    sb = pg.FamilyBasis(mesh, dim=2)
else:
    sb = fem.Basis(mesh, fem.ElementVector(fem.ElementQuad1()))
ms = Hyperelastic(sb, mat)
m_s = pg.lumped_mass(sb, rho)
x = sb.doflocs[:, ::2] if kind=="pg" else mesh.p
v0 = v0_of(mesh.p)
wall = lambda: RigidWall(axis=1, position=0.0, side=1)
T = float(sys.argv[2]) if len(sys.argv) > 2 else 0.02
import time
t0=time.perf_counter()
ts = pg.central_difference(ms, m_s, T, v0=v0, wall=wall(), verbose=False)
t1=time.perf_counter()
if kind == "pg":
    part = dist.Partition(mesh, comm); b = part.basis(dim=2)
else:
    part = dist.Partition(mesh, comm, fe_elements=np.arange(mesh.nelements)); b = part.fe_basis(fem.ElementVector(fem.ElementQuad1()))
md = Hyperelastic(b, mat)
m_d = dist.lumped_mass(b, part, rho)
t2=time.perf_counter()
td = dist.central_difference(md, part, m_d, T, v0=v0, wall=wall(), verbose=False)
t3=time.perf_counter()
e = np.abs(td.x - ts.x).max() / np.abs(ts.x).max()
ek = abs(td.history[-1]["kinetic"] - ts.history[-1]["kinetic"]) / ts.history[-1]["kinetic"]
if comm.rank == 0:
    print(kind, "steps", ts.steps, td.steps, "rel x", e, "rel T", ek, "D_c", ts.history[-1]["contact_loss"], td.history[-1]["contact_loss"], "t", t1-t0, t3-t2, ts.times, td.times)
