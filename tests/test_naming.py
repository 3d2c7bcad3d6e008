"""Thesis names (Table 7.1) <-> FamilyBasis options, with Table 7.1's
defaults: BC for first-order formulations, boundary variant sn, TL."""
import pytest

import skfem_pg as pg
from skfem_pg.naming import fe_method, formulation_of, parse
from conftest import cube, square


@pytest.mark.parametrize("name, expected", [
    ("VCBCPBG V5 Unl", dict(shape="MTE1", method="PBG", bond=True, vc="V5",
                            vc_boundary="sn")),
    # a verbatim Table 7.2 row (rejected before: V5 without BC)
    ("VCPBG V5sn Unl", dict(shape="MTE1", method="PBG", bond=True,
                            vc="V5", vc_boundary="sn")),
    ("VCPBG Unl", dict(shape="MTE1", method="PBG", bond=True, vc="V5",
                       vc_boundary="sn")),
    ("VCBCPBG V5sn Unl TL", dict(shape="MTE1", method="PBG", bond=True,
                                 vc="V5", vc_boundary="sn")),
    ("PBG Unl", dict(shape="MTE1", method="PBG", bond=True, vc=None)),
    ("PBG Unl TL noBC", dict(shape="MTE1", method="PBG", bond=False,
                             vc=None)),
    ("PBG U1", dict(shape="WTE1", method="PBG", bond=True, vc=None)),
    ("VCPPG V3sn Unl", dict(shape="MTE1", method="PPG1", bond=True,
                            vc="V3", vc_boundary="sn")),
    ("VCPPG Unl", dict(shape="MTE1", method="PPG1", bond=True, vc="V3",
                       vc_boundary="sn")),
    ("VCBCPBG V5p Unl", dict(shape="MTE1", method="PBG", bond=True,
                             vc="V5", vc_boundary="p")),
    ("VCBCPBG V5m Unl", dict(shape="MTE1", method="PBG", bond=True,
                             vc="V5", vc_boundary="min-norm")),
    ("VC2PBG V4m U2", dict(shape="WTE2", method="PBG", bond=False,
                           vc="VC2", vc_boundary="min-norm")),
    ("VC2PPG V1s U2", dict(shape="WTE2", method="PPG1", bond=False,
                           vc="VC2", vc_boundary="s")),
    ("VCPBG U2", dict(shape="WTE2", method="PBG", bond=False, vc="V3",
                      vc_boundary="sn")),
])
def test_parse(name, expected):
    kw, _ = parse(name)
    # thesis names keep the thesis' families and quadrature weights
    thesis = {"weights": "volume", "weight_exponent": 1}
    if expected["shape"] != "WTE2":  # WTE2: its own horizon
        thesis["families"] = "mesh"
    assert kw == {**expected, **thesis}


def test_knn_token_names_the_package_recipe():
    kw, _ = parse("VCBCPBG V5m Unl TL kNN")
    assert kw["families"] == "nearest" and kw["weights"] == "uniform" \
        and kw["weight_exponent"] == 0
    for bad in ("VCPPG V3m Unl kNN", "VCPBG U2 kNN"):
        with pytest.raises(ValueError, match="kNN"):
            parse(bad)
    tets = pg.Particles.from_mesh(cube(3, 0.2, seed=2, kind="tet"))
    b = pg.FamilyBasis(tets, dim=3)  # the keyword default on tetrahedra
    assert b.recipe == "kNN" and b.name == "VCBCPBG V5m Unl TL kNN"
    assert pg.FamilyBasis.from_name(tets, b.name, dim=3).recipe == "kNN"
    thesis = pg.FamilyBasis.from_name(tets, "VCBCPBG V5m Unl", dim=3)
    assert thesis.recipe == "mesh" and thesis.name == "VCBCPBG V5m Unl TL"
    assert thesis.weights == "volume" and thesis.weight_exponent == 1


def test_round_trip_writes_the_full_code():
    p = pg.Particles.from_mesh(square(6, 0.3, seed=1))
    for name in ("VCBCPBG V5m Unl TL", "BCPBG U1 TL", "VCBCPPG V3m Unl TL",
                 "PPG Unl TL noBC", "VCBCPBG V5sn Unl TL",
                 "VCPPG V3s Unl TL noBC", "VCBCPBG V5p Unl TL"):
        assert pg.FamilyBasis.from_name(p, name, dim=2).name == name
    b = pg.FamilyBasis.from_name(p, "VCPBG V5sn Unl", dim=2)
    assert b.vc_boundary == "sn" and b.bond and b.name_notes == []
    assert b.name == "VCBCPBG V5sn Unl TL"
    # the keyword API keeps its own defaults: min-norm
    assert pg.FamilyBasis(p, dim=2).name == "VCBCPBG V5m Unl TL"
    b = pg.FamilyBasis.from_name(p, "VCPBG Unl", dim=2,
                                 vc_boundary="min-norm")
    assert b.name == "VCBCPBG V5m Unl TL"


def test_fe_names():
    assert fe_method("FEM Q1P0") == "Q1P0" and fe_method("FEM H1") == "H1"
    assert fe_method("VCPBG Unl") is None
    with pytest.raises(ValueError, match="FE comparator"):
        fe_method("FEM Q3")
    with pytest.raises(ValueError, match="Scene.solve"):
        pg.FamilyBasis.from_name(pg.Particles.from_mesh(square(3)),
                                 "FEM Q1", dim=2)


def test_bad_names_are_named():
    with pytest.raises(ValueError, match="cannot read"):
        parse("VCBC V5 Unl")
    with pytest.raises(ValueError, match="cannot read"):
        parse("VCBCPBG UL Unl")
    with pytest.raises(ValueError, match="unknown formulation"):
        parse("VCPBG UnlP1")
    with pytest.raises(NotImplementedError, match="UL"):
        parse("VCBCPBG V5sn UnlP0 UL")
    with pytest.raises(NotImplementedError, match="UL is built for PBG"):
        parse("VCPPG Unl UL")
    with pytest.raises(ValueError, match="variant"):
        parse("BCPBG V5sn Unl")
    with pytest.raises(ValueError, match="first-order"):
        parse("BCPBG U2")
    with pytest.raises(NotImplementedError, match="'s'"):
        parse("VC2PBG U2")


def test_scene_solves_by_thesis_and_fe_names():
    import numpy as np
    import skfem as fem
    from skfem_pg import materials as mat
    from skfem_pg.scenes import Scene
    m = fem.MeshQuad.init_tensor(np.linspace(0, 4, 9), np.linspace(0, 1, 3))
    m = m.with_boundaries({"left": lambda x: x[0] == 0,
                           "right": lambda x: x[0] == 4})
    s = Scene("names", m, mat.NeoHooke(lam=2.0, mu=1.0), clamped=["left"],
              tractions={"right": [0.0, 0.01]}, probes={"tip": (4.0, 1.0)})
    a, b = s.solve("FEM Q1"), s.solve("Q1")
    assert a.method == "FEM Q1" and np.array_equal(a.u, b.u)
    c = s.solve("VCPBG Unl")
    d = s.solve("PG", vc_boundary="sn")
    assert c.basis.name == "VCBCPBG V5sn Unl TL"
    assert np.allclose(c.u, d.u, rtol=0, atol=1e-12)
    with pytest.raises(ValueError, match="unknown method"):
        s.solve("VCPBG")


#: every formulation name the thesis text uses (thesis Table 7.1 and its text)
THESIS_NAMES = [
    "PPG Unl", "PBG Unl", "BCPBG Unl", "VCBCPBG Unl", "VCPBG Unl",
    "VCPPG Unl", "VCPPG V1sn Unl", "VCPPG V2sn Unl", "VCPPG V3p Unl",
    "VCPPG V3s Unl", "VCPPG V3sn Unl", "VCPBG V5sn Unl", "VCPBG U1",
    "PBG U2", "VCPBG U2", "VC2PPG V1s U2", "PPG UnlP0", "PBG UnlP0",
    "VCPBG UnlP0", "VCPPG UnlP0", "VCPPG V1sn UnlP0", "VCPPG V2sn UnlP0",
    "VCPPG V3sn UnlP0", "PPG IUnlP0", "PBG U2P1", "VCPBG U2P1",
    "PBG U2P1C", "VCPBG U2P1C", "PBG Unl+P1C", "VCPBG Unl+P1C",
    "VCPBG U1SUnl", "PBG U1SIG", "VCPBG U1SIG", "VCBCPBG V5sn Unl+P1C TL"]


@pytest.mark.parametrize("name", THESIS_NAMES)
def test_every_thesis_name_parses(name):
    """The displacement basis of each formulation, with Table 7.1's
    defaults: BC for the first-order ones (U1, Unl and the mixed and
    stabilized formulations built on them), none for U2-based ones nor for
    U1SIG (its gradient lives at the master, where there is no bond;
    U1SUnl's basis is the MTE1 one its stabilization integrates)."""
    kw, _ = parse(name)
    form = formulation_of(name)
    assert name.split()[-1 if not name.endswith("TL") else -2] == form
    shape = {"U1": "WTE1", "U1SIG": "WTE1",
             "U2": "WTE2", "U2P1": "WTE2", "U2P1C": "WTE2"}.get(form, "MTE1")
    assert kw["shape"] == shape
    assert kw["bond"] == (shape != "WTE2" and form != "U1SIG")
    assert kw["method"] == ("PBG" if "PBG" in name else "PPG1")
    if name.startswith("VC"):
        assert kw["vc_boundary"] in ("sn", "s", "p")


def test_formulation_of():
    assert formulation_of("VCBCPBG V5sn UnlP0 TL") == "UnlP0"
    assert formulation_of("PPG IUnlP0") == "IUnlP0"
    assert formulation_of("FEM H1P0") == "H1P0"
    with pytest.raises(ValueError, match="cannot read"):
        formulation_of("UnlP0")


def test_knn_name_only_where_the_recipe_applies():
    """``knn_name``: the name with ``kNN`` for PBG on MTE1, None where the
    recipe is refused (PPG, WTE1's U1SIG, WTE2's U2 family)."""
    from skfem_pg.naming import knn_name
    assert knn_name("VCPBG V5m Unl+P1C") == "VCPBG V5m Unl+P1C kNN"
    assert knn_name("VCBCPBG V5m U1SUnl") == "VCBCPBG V5m U1SUnl kNN"
    for name in ("VCPBG V3m U1SIG", "VCPBG V3m U2P1", "VCPPG UnlP0",
                 "VCPBG V3m U2"):
        assert knn_name(name) is None


def test_a_formulation_of_ones_own_is_one_registration():
    """Item 2 of issue 29: a formulation written outside the package,
    registered through the public call, parses, builds and is solved by
    Scene.solve and by newton.  Here: Unl with its internal force and
    tangent doubled, so it carries twice the load of Unl at the same u."""
    import numpy as np
    import skfem as fem
    from skfem_pg.formulations import Hyperelastic, model_for
    from skfem_pg.materials import NeoHooke
    from skfem_pg.scenes import Scene

    class Doubled(Hyperelastic):
        def internal_force(self, state):
            return 2.0 * super().internal_force(state)

        def tangent(self, state):
            return 2.0 * super().tangent(state)

    pg.register_formulation("UnlX2", "MTE1",
                            lambda basis, material, tangent:
                            Doubled(basis, material, tangent=tangent))
    try:
        mesh = _strip()

        def scene(t):
            return Scene("own", mesh, NeoHooke(lam=10.0, mu=5.0), clamped=["left"],
                         tractions={"right": [0.0, t]},
                         probes={"tip": (4.0, 1.0)}, steps=2)
        kw, _ = parse("VCBCPBG V5m UnlX2")
        assert kw["shape"] == "MTE1" and kw["bond"]
        own = scene(0.2).solve("VCBCPBG V5m UnlX2", tol=1e-12)
        ref = scene(0.1).solve("VCBCPBG V5m Unl", tol=1e-12)
        assert np.abs(own.u - ref.u).max() <= 1e-9 * np.abs(ref.u).max()
        basis = own.basis
        model = model_for("UnlX2", basis, NeoHooke(lam=10.0, mu=5.0))
        assert isinstance(model, Doubled)
        u, _ = pg.solvers.newton(model, own.f_ext, D=basis.get_dofs("left"),
                                 steps=2, tol=1e-12, verbose=False)
        assert np.abs(u - own.u).max() <= 1e-9 * np.abs(own.u).max()
        with pytest.raises(ValueError, match="registered already"):
            pg.register_formulation("UnlX2", "MTE1", Doubled)
        with pytest.raises(ValueError, match="shape must be one of"):
            pg.register_formulation("Bad", "MTE3", Doubled)
    finally:
        pg.registry.unregister("UnlX2")
    with pytest.raises(ValueError, match="unknown formulation 'UnlX2'"):
        parse("VCPBG UnlX2")


def test_a_registered_builder_must_return_a_model():
    from skfem_pg.formulations import Model, model_for
    from skfem_pg.materials import NeoHooke
    import numpy as np
    import skfem as fem
    basis = pg.FamilyBasis(fem.MeshQuad.init_tensor(*[np.linspace(0, 1, 4)]
                                                    * 2), dim=2)
    assert isinstance(model_for("Unl", basis, NeoHooke(lam=1.0, mu=1.0)), Model)
    pg.register_formulation("NotAModel", "MTE1", lambda b, m, t: object())
    try:
        with pytest.raises(TypeError, match="'NotAModel' built a object "
                           "without basis, n_u, N"):
            model_for("NotAModel", basis, NeoHooke(lam=1.0, mu=1.0))
    finally:
        pg.registry.unregister("NotAModel")


def test_an_fe_comparator_of_ones_own_is_one_registration():
    """The FE comparators live in the same registry: a registered one is
    a method name of Scene.solve (here Q1 with a 3 x 3 Gauss rule: exact
    to degree 4)."""
    import numpy as np
    import skfem as fem
    from skfem_pg.materials import NeoHooke
    from skfem_pg.scenes import Scene
    pg.registry.register_fe("Q1G3", fem.MeshQuad1, fem.ElementQuad1,
                            intorder=4)
    try:
        mesh = _strip()
        sc = Scene("own-fe", mesh, NeoHooke(lam=10.0, mu=5.0), clamped=["left"],
                   tractions={"right": [0.0, 0.1]},
                   probes={"tip": (4.0, 1.0)})
        g3, q1 = sc.solve("FEM Q1G3"), sc.solve("Q1")
        assert g3.basis.X.shape[1] == 9 and q1.basis.X.shape[1] == 4
        assert np.abs(g3.u - q1.u).max() <= 0.05 * np.abs(q1.u).max()
        assert fe_method("FEM Q1G3") == "Q1G3"
    finally:
        pg.registry.unregister_fe("Q1G3")
    with pytest.raises(ValueError, match="unknown FE comparator"):
        fe_method("FEM Q1G3")


def test_the_registry_routes_every_frame_and_reserves_fe_names():
    """Issue 47: an FE comparator's name is not a formulation token (the
    FE method won and the builder was never called); a user's formulation
    claiming the UL frame is refused unless it builds its own UL model,
    which the scene then calls (the scene built the package's UL
    displacement model: 44 % off, no word); a builder of the wrong
    signature is refused where it is registered, not in a bare TypeError
    at the solve."""
    import numpy as np
    import skfem as fem
    from skfem_pg.formulations import Hyperelastic, UpdatedLagrange
    from skfem_pg.materials import NeoHooke
    from skfem_pg.scenes import Scene

    def build(basis, material, tangent):
        return Hyperelastic(basis, material, tangent=tangent)
    with pytest.raises(ValueError, match="'Q1' is the name of an FE"):
        pg.register_formulation("Q1", "MTE1", build)
    with pytest.raises(ValueError, match="build must be callable as"):
        pg.register_formulation("Two", "MTE1", lambda basis, material: 0)
    with pytest.raises(ValueError, match="updated_lagrangian=build_ul"):
        pg.register_formulation("MyUL", "MTE1", build,
                                updated_lagrangian=True)
    built = []

    def build_ul(basis, material, every):
        built.append(every)
        return UpdatedLagrange(basis, material, every=every)
    pg.register_formulation("MyUL", "MTE1", build,
                            updated_lagrangian=build_ul)
    try:
        mesh = _strip()
        sc = Scene("own", mesh, NeoHooke(lam=10.0, mu=5.0), clamped=["left"],
                   tractions={"right": [0.0, 0.1]}, steps=2)
        basis, model, *_ = sc.setup("VCPBG V5m MyUL UL")
        assert built == [1] and isinstance(model, UpdatedLagrange)
        basis, model, *_ = sc.setup("VCPBG V5m MyUL")
        assert built == [1] and type(model) is Hyperelastic
    finally:
        pg.registry.unregister("MyUL")


def _strip():
    """A 4 x 1 strip of 8 x 2 quadrilaterals, its ends named."""
    import numpy as np
    import skfem as fem
    return fem.MeshQuad.init_tensor(
        np.linspace(0, 4, 9), np.linspace(0, 1, 3)).with_boundaries(
        {"left": lambda x: np.isclose(x[0], 0),
         "right": lambda x: np.isclose(x[0], 4)})


@pytest.mark.parametrize("kw", [
    {}, dict(families="mesh"), dict(families="horizon"),
    dict(families="nearest"), dict(families="nearest", weights="volume"),
    dict(weight_exponent=0.5), dict(shape="WTE1", bond=False, vc="V3"),
    dict(shape="WTE2"), dict(shape="WTE2", families="horizon"),
    dict(shape="WTE2", family_quadrature="moments"),
    dict(method="PPG1"), dict(method="PPG1", families="nearest"),
    dict(method="PPG1", test_shape="LME", lme_mu=2.5),
    dict(vc_boundary="p"), dict(vc_solver="local"), dict(vc=None),
    dict(vc_solver="lsqr", vc_exclude=[0, 1]),
])
def test_every_basis_name_gives_the_basis_back(kw):
    """name_of prints what Table 7.1 has no word for as k=v options: the
    spec of the name is the spec named (given arrays passed beside)."""
    from skfem_pg.discretization import BasisSpec
    p = pg.Particles.from_mesh(square(5, 0.2, seed=3))
    spec = BasisSpec.resolve(p, dim=2, **kw)
    beside = {k: kw[k] for k in ("vc_exclude",) if k in kw}
    back, _ = BasisSpec.from_name(p, spec.name, dim=2, **beside)
    assert back == spec, spec.name


def test_a_family_rule_of_ones_own_is_named():
    """A rule added to RULES: the basis' name says so and gives it back;
    given families are named 'given' and must be passed beside."""
    from skfem_pg.discretization import BasisSpec, families
    p = pg.Particles.from_mesh(square(5, 0.2, seed=3))
    rules = dict(families.RULES, wide=lambda q: families.horizon(
        q, factor=2.2))
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(families, "RULES", rules)
        b = pg.FamilyBasis(p, "wide", dim=2)
        assert b.name == "VCBCPBG V5m Unl TL families=wide"
        assert BasisSpec.from_name(p, b.name, dim=2)[0] == b.spec
    fam = families.nearest(p, 7)
    spec = BasisSpec.resolve(p, dim=2, families=fam)
    assert spec.name.endswith("families=given")
    with pytest.raises(ValueError, match="pass families="):
        BasisSpec.from_name(p, spec.name, dim=2)
    assert BasisSpec.from_name(p, spec.name, dim=2, families=fam)[0] == spec
    with pytest.raises(ValueError, match="unknown option 'familes'"):
        parse("VCPBG Unl familes=mesh")
