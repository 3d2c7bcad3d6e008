"""The discretization recipe: a resolved BasisSpec, stages composed by one
builder, and a new stage added by one registration."""
import numpy as np
import pytest
import skfem as fem

import skfem_pg as pg
from skfem_pg.discretization import BasisSpec, builder, parts


@pytest.fixture
def particles():
    return pg.Particles.from_mesh(fem.MeshTri.init_sqsymmetric().refined(2))


def test_spec_resolves_defaults_once(particles):
    s = BasisSpec.resolve(particles, dim=2)
    assert (s.shape, s.bond, s.vc, s.method, s.weights, s.weight_exponent,
            s.family_rule, s.recipe) == (
                "MTE1", True, "V5", "PBG", "uniform", 0.0,
                parts.FamilyRule("mesh"), "meshU")  # triangles
    assert s.grouped  # the default runs per size group, unpadded
    p = BasisSpec.resolve(particles, dim=2, method="PPG1")
    assert (p.vc, p.grouped) == ("V3", False)


@pytest.mark.parametrize("kw", [{}, {"method": "PPG1"},
                                {"shape": "WTE1"},
                                {"vc_boundary": "s"},
                                {"shape": "WTE2",
                                 "family_quadrature": "moments"}])
def test_from_spec_is_the_keyword_constructor(particles, kw):
    a = pg.FamilyBasis(particles, dim=2, **kw)
    b = pg.FamilyBasis.from_spec(particles,
                                 BasisSpec.resolve(particles, dim=2, **kw))
    assert np.array_equal(a.G, b.G) and np.array_equal(a.dx, b.dx)
    assert a.options == b.options == b.spec.options()
    if a.test is not None:
        assert np.array_equal(a.test.G, b.test.G)
    # the options rebuild the same basis (what updated Lagrange does)
    c = pg.FamilyBasis(particles, **a.options)
    assert np.array_equal(a.G, c.G)


def test_name_parser_produces_the_spec(particles):
    s, notes = BasisSpec.from_name(particles, "VCBCPBG V5 Unl", dim=2)
    # a thesis name means the thesis' recipe, whatever the keyword default
    assert s == BasisSpec.resolve(particles, dim=2, shape="MTE1", bond=True,
                                  vc="V5", vc_boundary="sn", families="mesh")
    assert (s.weights, s.weight_exponent) == ("volume", 1.0)
    u, _ = BasisSpec.from_name(particles, "VCBCPBG V5m Unl TL meshU", dim=2)
    assert u == BasisSpec.resolve(particles, dim=2)  # the 2-D tri default
    assert s.vc_boundary == "sn"  # the thesis' boundary variant
    b = pg.FamilyBasis.from_name(particles, "VCBCPPG V3sn Unl TL", dim=2)
    assert b.spec.method == "PPG1" and b.name == "VCBCPPG V3sn Unl TL"


def test_conflicting_options_are_refused_before_any_stage(particles):
    with pytest.raises(ValueError, match="vc='V5'.*bond=True"):
        BasisSpec.resolve(particles, dim=2, vc="V5", bond=False)
    with pytest.raises(ValueError, match="test_shape"):
        BasisSpec.resolve(particles, dim=2, test_shape="WLS1")


def test_a_new_test_rule_is_one_registration(particles, monkeypatch):
    """A PPG test rule added to TEST_GRADIENTS: accepted by the keyword
    constructor, run by the builder, VC-corrected like the others."""
    calls = []

    def scaled_master(p, fam, G, spec):  # a deliberately poor rule
        calls.append(len(fam.masters))
        return 0.5 * G[:, 0]

    monkeypatch.setitem(builder.TEST_GRADIENTS, "half", scaled_master)
    plain = pg.FamilyBasis(particles, dim=2, method="PPG1", vc=None)
    half = pg.FamilyBasis(particles, dim=2, method="PPG1", vc=None,
                          test_shape="half")
    assert calls == [particles.n]
    assert np.allclose(half.test.G, 0.5 * plain.test.G)
    # through the VC stage like a built-in rule: WTE1 under a new name
    monkeypatch.setitem(builder.TEST_GRADIENTS, "static",
                        builder.TEST_GRADIENTS["WTE1"])
    new = pg.FamilyBasis(particles, dim=2, method="PPG1", test_shape="static")
    ref = pg.FamilyBasis(particles, dim=2, method="PPG1", test_shape="WTE1")
    assert np.array_equal(new.test.G, ref.test.G)
    assert new.vc_report.residual_after < 1e-10


def test_a_new_correction_is_one_registration(particles, monkeypatch):
    """A correction registered in CORRECTIONS is the stage the builder runs
    for its (method, order) key."""
    original, seen = builder.CORRECTIONS["PBG", 1], []

    def recording(c):
        seen.append((c.spec.method, c.spec.vc))
        original(c)

    monkeypatch.setitem(builder.CORRECTIONS, ("PBG", 1), recording)
    b = pg.FamilyBasis(particles, dim=2, vc_boundary="s")
    assert seen == [("PBG", "V5")]  # the padded pipeline's stage
    monkeypatch.setitem(builder.CORRECTIONS, ("PBG", 1), original)
    ref = pg.FamilyBasis(particles, dim=2, vc_boundary="s")
    assert np.array_equal(b.G, ref.G)
