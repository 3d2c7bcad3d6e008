"""Thesis names (Table 7.1) <-> FamilyBasis options."""
import pytest

import skfem_pg as pg
from skfem_pg.naming import parse
from conftest import square


@pytest.mark.parametrize("name, expected", [
    ("VCBCPBG V5 Unl", dict(shape="MTE1", method="PBG", bond=True, vc="V5")),
    ("PBG U1", dict(shape="WTE1", method="PBG", bond=False, vc=None)),
    ("VCPPG V3sn Unl", dict(shape="MTE1", method="PPG1", bond=False,
                            vc="V3", vc_boundary="sn")),
    ("VCBCPBG V5p Unl", dict(shape="MTE1", method="PBG", bond=True,
                             vc="V5", vc_boundary="p")),
    ("VC2PBG V4 U2", dict(shape="WTE2", method="PBG", bond=False,
                          vc="VC2")),
    ("VC2PPG V1s U2", dict(shape="WTE2", method="PPG1", bond=False,
                           vc="VC2", vc_boundary="s")),
    ("VCBCPPG Unl", dict(shape="MTE1", method="PPG1", bond=True, vc="V3")),
])
def test_parse(name, expected):
    kw, _ = parse(name)
    assert kw == expected


def test_round_trip_and_notes():
    p = pg.Particles.from_mesh(square(6, 0.3, seed=1))
    for name in ("VCBCPBG V5 Unl", "PBG U1", "VCBCPPG V3 Unl", "PPG Unl",
                 "VCBCPBG V5sn Unl", "VCPPG V3s Unl", "VCBCPBG V5p Unl"):
        assert pg.FamilyBasis.from_name(p, name, dim=2).name == name
    b = pg.FamilyBasis.from_name(p, "VCPPG V3sn Unl", dim=2)
    assert b.vc_boundary == "sn" and b.name_notes == []
    assert pg.FamilyBasis(p, dim=2).name == "VCBCPBG V5 Unl"


def test_bad_names_are_named():
    with pytest.raises(ValueError, match="cannot read"):
        parse("VCBC V5 Unl")
    with pytest.raises(NotImplementedError, match="UnlP0"):
        parse("VCPPG V3sn UnlP0")
    with pytest.raises(ValueError, match="variant without"):
        parse("BCPBG V5sn Unl")
