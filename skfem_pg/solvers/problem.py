r"""A model and what acts on it, as one record the drivers take.

FElupe poses a problem as a ``SolidBody`` and the boundaries and loads of a
``Step``; scikit-fem hands ``solve(*condense(K, f, D=D))`` its system and
Dirichlet dofs.  :class:`Problem` is the record between: the model (the
protocol of :mod:`skfem_pg.formulations.protocol`), its external forces,
prescribed dofs and values, rigid walls and lumped mass.  The drivers
:func:`~skfem_pg.solvers.newton`, :func:`~skfem_pg.solvers.newmark`,
:func:`~skfem_pg.solvers.central_difference` and their MPI twins take it in
place of the model (the keywords ``f_ext``, ``D``, ``u_D``, ``wall`` and
``m`` stay as a convenience; giving both raises); the options of a run
are the :mod:`~skfem_pg.solvers.controls` records, the results named
records (:class:`Solution`, :class:`~skfem_pg.solvers.dynamics.Trajectory`).

>>> import numpy as np, skfem as fem, skfem_pg as pg
>>> from skfem_pg.formulations import Hyperelastic
>>> from skfem_pg.materials import NeoHooke
>>> mesh = fem.MeshQuad.init_tensor(np.linspace(0, 4, 9), np.linspace(0, 1, 3))
>>> basis = pg.FamilyBasis(mesh, dim=2)
>>> f = np.zeros(basis.N)
>>> f[basis.get_dofs(lambda x: x[0] == 4).nodal["u^2"]] = -0.02
>>> model = Hyperelastic(basis, NeoHooke(lam=10.0, mu=4.0))
>>> problem = pg.solvers.Problem(model, f_ext=f,
...                              D=basis.get_dofs(lambda x: x[0] == 0))
>>> sol = pg.solvers.newton(problem, verbose=False)
>>> sol.x.shape == (basis.N,), len(sol.history)
(True, 1)
"""
import dataclasses
from typing import Any, NamedTuple

import numpy as np

from ..formulations.protocol import require_model
from .rates import refuse_rate_dependent

#: the convenience keywords of the drivers and the field each fills
KEYWORDS = {"f_ext": "f_ext", "D": "D", "u_D": "u_D", "wall": "walls",
            "m": "mass"}


@dataclasses.dataclass(frozen=True)
class Problem:
    """A model with its loads, Dirichlet data, walls and mass.

    Parameters
    ----------
    model
        A model of :mod:`skfem_pg.formulations` (FE or PG), checked
        against the model protocol.
    f_ext
        External forces: a vector (at load factor 1 in a static run,
        constant in a dynamic one; one entry per displacement dof or per
        unknown) or a callable of the load factor / time; ``None``: none.
    D
        Prescribed dofs (indices or a scikit-fem ``DofsView``).
    u_D
        Their values: a vector (scaled by the load factor in a static
        run) or a callable of the load factor / time; ``None``: zero.
    walls
        :class:`~skfem_pg.solvers.RigidWall` objects (one, a list or
        none); the drivers bind copies, so a wall may serve several
        runs.
    mass
        The diagonal (lumped) mass per displacement dof
        (:func:`~skfem_pg.solvers.lumped_mass`); dynamic runs need it.

    The vectors are kept as given: a driver checks their sizes against
    the model (an MPI driver against the serial numbering).

    Examples
    --------
    >>> import skfem as fem, skfem_pg as pg
    >>> from skfem_pg.formulations import Hyperelastic
    >>> from skfem_pg.materials import NeoHooke
    >>> basis = pg.FamilyBasis(fem.MeshQuad().refined(2), dim=2)
    >>> problem = Problem(Hyperelastic(basis, NeoHooke(lam=60.0, mu=40.0)),
    ...                   D=basis.get_dofs(lambda x: x[0] == 0),
    ...                   walls=pg.solvers.RigidWall(1))
    >>> len(problem.walls), problem.replace(mass=pg.lumped_mass(
    ...     basis, 1.0)).mass.shape
    (1, (50,))

    """

    model: Any
    f_ext: Any = None
    D: Any = None
    u_D: Any = None
    walls: tuple = ()
    mass: Any = None

    def __post_init__(self):
        require_model(self.model, "Problem")
        from .contact import RigidWall
        walls = self.walls
        if walls is None:
            walls = ()
        elif isinstance(walls, RigidWall):
            walls = (walls,)
        walls = tuple(walls)
        for w in walls:
            if not isinstance(w, RigidWall):
                raise TypeError("Problem(walls=...): {!r} is not a "
                                "RigidWall".format(w))
        object.__setattr__(self, "walls", walls)
        if self.mass is not None:
            object.__setattr__(self, "mass",
                               np.asarray(self.mass, dtype=float))

    @classmethod
    def of(cls, problem, driver, **keywords):
        """``problem`` if it is a :class:`Problem`, else the problem of the
        model ``problem`` and the driver's convenience ``keywords``
        (``f_ext``, ``D``, ``u_D``, ``wall``, ``m``; ``None``: not
        given).  Keywords beside a :class:`Problem` raise ``TypeError``
        naming them: one of the two would be ignored."""
        given = {k: v for k, v in keywords.items() if v is not None}
        if isinstance(problem, cls):
            if given:
                raise TypeError(
                    "{}(problem, {}): a Problem carries its {}; give them "
                    "to the Problem (or dataclasses.replace(problem, ...))"
                    .format(driver, ", ".join(k + "=" for k in given),
                            ", ".join(KEYWORDS[k] for k in given)))
            out = problem
        else:
            require_model(problem, driver)  # named after the driver called
            out = cls(problem, **{KEYWORDS[k]: v for k, v in given.items()})
        if driver != "newmark":
            refuse_rate_dependent(out.model, driver)
        return out

    def replace(self, **changes):
        """A copy with ``changes`` (fields of :class:`Problem`)."""
        return dataclasses.replace(self, **changes)

    def require_mass(self, driver):
        """The mass, or ``ValueError`` naming the driver that needs it."""
        if self.mass is None:
            raise ValueError("{} integrates M a + f_int = f_ext: give the "
                             "lumped mass (Problem(..., mass=m) or m=)"
                             .format(driver))
        return self.mass


class Solution(NamedTuple):
    """What :func:`~skfem_pg.solvers.newton` returns: ``x``, all unknowns
    (the displacements are ``x[:model.n_u]``), and ``history``, a dict
    per converged load step.  Unpacks as ``x, history = ...``.

    Examples
    --------
    >>> sol = Solution(x=[0.0, 1.0], history=[{"load": 1.0}])
    >>> x, history = sol
    >>> sol.history[-1]["load"]
    1.0

    """

    x: np.ndarray
    history: list


__all__ = ["KEYWORDS", "Problem", "Solution"]
