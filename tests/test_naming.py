"""Thesis names (Table 7.1) <-> FamilyBasis options, with Table 7.1's
defaults: BC for first-order formulations, boundary variant sn, TL."""
import pytest

import skfem_pg as pg
from skfem_pg.naming import fe_method, parse
from conftest import square


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
    assert kw == expected


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
    for name in ("VCPPG V3sn UnlP0", "PPG IUnlP0", "VCPBG U1SIG",
                 "VCBCPBG V5sn Unl+P1C TL", "VCBCPBG UL Unl"):
        with pytest.raises((NotImplementedError, ValueError)):
            parse(name)
    with pytest.raises(NotImplementedError, match="UL"):
        parse("VCBCPBG V5sn Unl UL")
    with pytest.raises(NotImplementedError, match="UnlP0"):
        parse("VCPPG V3sn UnlP0")
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
    s = Scene("names", m, mat.NeoHooke(2.0, 1.0), clamped=["left"],
              tractions={"right": [0.0, 0.01]}, probes={"tip": (4.0, 1.0)})
    a, b = s.solve("FEM Q1"), s.solve("Q1")
    assert a.method == "FEM Q1" and np.array_equal(a.u, b.u)
    c = s.solve("VCPBG Unl")
    d = s.solve("PG", vc_boundary="sn")
    assert c.basis.name == "VCBCPBG V5sn Unl TL"
    assert np.allclose(c.u, d.u, rtol=0, atol=1e-12)
    with pytest.raises(ValueError, match="unknown method"):
        s.solve("VCPBG")
