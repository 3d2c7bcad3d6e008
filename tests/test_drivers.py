"""One load-stepping driver and the drivers' option records: the serial
and distributed Newton share load_stepping / newton_iterations (the linear
algebra injected), and every driver takes its controls as one record or as
keywords of the record's fields."""
import numpy as np
import pytest
import skfem as fem

import skfem_pg as pg
from skfem_pg import materials as mat
from skfem_pg.formulations import Hyperelastic
from skfem_pg.solvers import (ExplicitControls, NewmarkControls,
                              NewtonControls, central_difference,
                              lumped_mass, newmark, newton)
from skfem_pg.solvers import static


@pytest.fixture(scope="module")
def beam():
    mesh = fem.MeshQuad.init_tensor(np.linspace(0, 4, 9),
                                    np.linspace(0, 1, 3))
    mesh = mesh.with_boundaries({"left": lambda x: np.isclose(x[0], 0),
                                 "right": lambda x: np.isclose(x[0], 4)})
    b = pg.FamilyBasis(mesh, dim=2)
    return b, pg.traction(b, "right", [0.0, 0.02]), b.get_dofs("left")


def test_record_and_keywords_are_the_same_run(beam):
    b, f, D = beam
    model = Hyperelastic(b, mat.NeoHooke(lam=100.0, mu=40.0))
    c = NewtonControls(steps=2, tol=1e-11, predictor=False, verbose=False)
    x1, h1 = newton(model, f, D=D, controls=c)
    x2, h2 = newton(model, f, D=D, steps=2, tol=1e-11, predictor=False,
                    verbose=False)
    x3, h3 = newton(model, f, D=D, controls=c, steps=1)  # keyword wins
    assert np.array_equal(x1, x2) and len(h1) == len(h2) == 2
    assert len(h3) == 1 and np.allclose(x3, x1, atol=1e-9 * abs(x1).max())


def test_controls_are_checked_by_name():
    with pytest.raises(TypeError, match="tolerance.*NewtonControls"):
        NewtonControls.of(tolerance=1e-9)
    with pytest.raises(ValueError, match="tol must be a positive"):
        NewtonControls(tol=-1.0)
    with pytest.raises(ValueError, match="min_step"):
        NewtonControls(min_step=0.0)
    with pytest.raises(TypeError, match="controls must be a NewmarkControls"):
        NewmarkControls.of(NewtonControls())
    with pytest.raises(ValueError, match="beta and gamma"):
        NewmarkControls(beta=0.0)
    with pytest.raises(ValueError, match="output_every"):
        NewmarkControls(output_every=0)
    with pytest.raises(ValueError, match="safety"):
        ExplicitControls(safety=-0.5)
    with pytest.raises(ValueError, match="estimate_every"):
        ExplicitControls(estimate_every=2.5)


def test_controls_that_ran_into_a_wrong_reason_are_refused():
    """Issue 47: a safety factor above 1 ran unstable and stopped as an
    "inverted point", beta = inf as "J <= 0", 10 million load steps as
    "diverging" (below min_step), gamma = 0.3 returned a trajectory with a
    49 % energy error."""
    with pytest.raises(ValueError, match=r"safety must be a factor in "
                                         r"\(0, 1\]"):
        ExplicitControls(safety=3.0)
    ExplicitControls(safety=1.0)
    with pytest.raises(ValueError, match="beta and gamma must be positive "
                                         "numbers"):
        NewmarkControls(beta=np.inf)
    with pytest.raises(ValueError, match="gamma = 0.3 < 1/2"):
        NewmarkControls(gamma=0.3)
    NewmarkControls(beta=1.0 / 6.0, gamma=0.5)  # linear acceleration
    with pytest.raises(ValueError, match="below min_step"):
        NewtonControls(steps=10_000_000)
    NewtonControls(steps=10_000_000, min_step=1e-8)
    NewtonControls(steps=10_000_000, adaptive=False)


def test_the_linear_algebra_is_injected(beam):
    """load_stepping + newton_iterations with a wrapped SerialAlgebra (what
    the distributed Newton does with PETSc's): the same answer as newton,
    and every solve went through the injected object."""
    b, f, D = beam
    model = Hyperelastic(b, mat.NeoHooke(lam=100.0, mu=40.0))
    x_ref, _ = newton(model, f, D=D, steps=2, verbose=False)
    Dd = np.asarray(D.flatten())
    I = np.setdiff1d(np.arange(b.N), Dd)
    lin = static.condensed_solver("direct", b, I)
    solves = []

    class Counting(static.SerialAlgebra):
        def solve(self, *args):
            solves.append(1)
            return super().solve(*args)

    algebra = Counting(model, f, Dd, I, lin)
    c = NewtonControls(steps=2, verbose=False)

    def step(start, target):
        return static.newton_iterations(model, algebra, start, target,
                                        np.zeros(len(Dd)), c.tol, c.maxiter)

    x, hist = static.load_stepping(model, step, algebra, np.zeros(b.N), 0.0,
                                   0.5, c)
    assert np.allclose(x, x_ref, rtol=0, atol=1e-12 * abs(x_ref).max())
    assert len(solves) == sum(len(h["residuals"]) - 1 for h in hist) > 0


def test_dynamics_take_their_records(beam):
    b, f, D = beam
    model = Hyperelastic(b, mat.NeoHooke(lam=100.0, mu=40.0))
    m = lumped_mass(b, 1.0)
    a = newmark(model, m, 0.2, 0.05, f_ext=f, D=D,
                controls=NewmarkControls(output_every=2, verbose=False))
    k = newmark(model, m, 0.2, 0.05, f_ext=f, D=D, output_every=2,
                verbose=False)
    assert np.array_equal(a.x, k.x) and len(a.history) == 3
    e = central_difference(model, m, 0.05, f_ext=f, D=D,
                           controls=ExplicitControls(safety=0.5,
                                                     verbose=False))
    k = central_difference(model, m, 0.05, f_ext=f, D=D, safety=0.5,
                           verbose=False)
    assert np.array_equal(e.x, k.x) and e.steps == k.steps > 1


def test_drivers_name_what_a_model_lacks(beam):
    """The drivers take a model by its protocol (issue 49: no
    ``getattr(model, "N", basis.N)`` fallbacks): an object without ``N``
    is refused where it enters, naming the driver and the member."""
    model = Hyperelastic(beam[0], mat.NeoHooke(lam=100.0, mu=40.0))

    class NoN:
        def __getattr__(self, name):
            if name == "N":
                raise AttributeError(name)
            return getattr(model, name)
    for run, name in ((lambda m: pg.solvers.newton(m), "newton"),
                      (lambda m: pg.solvers.newmark(
                          m, np.eye(1), 1.0, 1e-3), "newmark"),
                      (lambda m: pg.solvers.central_difference(
                          m, np.ones(1), 1.0), "central_difference"),
                      (lambda m: pg.solvers.checkpoint.save(
                          "x", m, np.zeros(3)), "checkpoint.save")):
        with pytest.raises(TypeError, match=name + ".*lacks N"):
            run(NoN())


def test_a_problem_is_the_same_run_as_the_keywords(beam):
    """Issue 49: model, loads, Dirichlet data, walls and mass as one record
    (pg.Problem); each driver gives the keyword run's numbers bit for bit,
    and a keyword beside a Problem is refused, naming it."""
    b, f, D = beam
    model = Hyperelastic(b, mat.NeoHooke(lam=100.0, mu=40.0))
    problem = pg.Problem(model, f_ext=f, D=D)
    sol = newton(problem, verbose=False)
    x, hist = newton(model, f, D=D, verbose=False)
    assert np.array_equal(sol.x, x) and len(sol.history) == len(hist)
    m = lumped_mass(b, 1.0)
    dyn = problem.replace(mass=m)
    a = newmark(dyn, t_end=0.5, dt=0.1, verbose=False)
    k = newmark(model, m, 0.5, 0.1, f_ext=f, D=D, verbose=False)
    assert np.array_equal(a.x, k.x) and np.array_equal(a.v, k.v)
    a = central_difference(dyn, t_end=0.02, verbose=False)
    k = central_difference(model, m, 0.02, f_ext=f, D=D, verbose=False)
    assert np.array_equal(a.x, k.x) and a.steps == k.steps
    with pytest.raises(TypeError, match=r"newton\(problem, f_ext=\)"):
        newton(problem, f)
    with pytest.raises(TypeError, match="carries its mass"):
        newmark(dyn, 0.5, 0.1)  # t_end in the mass' place
    with pytest.raises(ValueError, match="give the lumped mass"):
        central_difference(problem, t_end=0.02)
    with pytest.raises(TypeError, match="is not a RigidWall"):
        pg.Problem(model, walls=[1.0])


def test_a_wall_serves_several_runs_unchanged():
    """The drivers bind copies of the walls: a wall without tol takes the
    default of each body it meets (it kept the first body's before)."""
    from skfem_pg.solvers import RigidWall
    wall = RigidWall(0, 0.0)
    for length in (1.0, 100.0):
        mesh = fem.MeshQuad.init_tensor(np.linspace(0, length, 5),
                                        np.linspace(0, 1, 2))
        b = pg.FamilyBasis(mesh, dim=2)
        model = Hyperelastic(b, mat.NeoHooke(lam=100.0, mu=40.0))
        v0 = np.where(np.arange(b.N) % 2 == 0, -0.1, 0.0)
        central_difference(model, lumped_mass(b, 1.0), 0.01, v0=v0,
                           wall=wall, verbose=False)
        assert wall.tol is None and not hasattr(wall, "dofs")
