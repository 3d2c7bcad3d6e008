r"""Thesis names of PG formulations (Table 7.1) <-> ``FamilyBasis`` options.

A name reads ``[VC|VC2][BC]{PBG|PPG|PPG1|PPG2} [V1..V5][p|s|sn] {U1|Unl|U2}``,
e.g. ``"VCBCPBG V5sn Unl"`` or ``"PPG Unl"``:

==========  ==============================================================
``VC``      first-order variational consistency, variant ``V1``…``V5``
            (default V5 with BC, else V3; VC2: the second-order correction)
``BC``      bond correction
``PBG``     Bubnov–Galerkin; ``PPG`` = ``PPG1`` Petrov–Galerkin (4.21),
            ``PPG2`` (4.22)
``U1``      WTE1 (classical correspondence), ``Unl`` MTE1, ``U2`` WTE2
==========  ==============================================================

The thesis' boundary variants ``p``, ``s``, ``sn`` of the VC system (fixed
correction at selected particles / at surface particles / normal component
at surface particles) map to ``vc_boundary`` (:mod:`skfem_pg.vc_boundary`);
without a suffix the package's minimum-norm solve is used
(``vc_boundary="min-norm"``).  Mixed formulations (``UnlP0``, ``U2P1``,
``Unl+P1C``, ...) are not implemented.
"""
import re

SHAPES = {"U1": "WTE1", "Unl": "MTE1", "U2": "WTE2"}
_NAME = re.compile(r"^(?P<vc>VC2|VC)?(?P<bc>BC)?(?P<method>PBG|PPG1|PPG2|PPG)"
                   r"(?:\s+(?P<variant>V[1-5])(?P<boundary>sn|s|p)?)?"
                   r"\s+(?P<form>\S+)$")


def parse(name):
    """``(kwargs, notes)`` for :class:`~skfem_pg.FamilyBasis` from a
    thesis name; raises ``ValueError`` naming what is not understood."""
    m = _NAME.match(name.strip())
    if m is None:
        raise ValueError("cannot read the formulation name {!r}; expected "
                         "e.g. 'VCBCPBG V5sn Unl' or 'PPG Unl'".format(name))
    g = m.groupdict()
    form = g["form"]
    if form not in SHAPES:
        raise NotImplementedError(
            "formulation {!r} is not available: displacement formulations "
            "U1, Unl, U2 only (mixed ones come later)".format(form))
    method = {"PPG": "PPG1"}.get(g["method"], g["method"])
    kw = {"shape": SHAPES[form], "method": method, "bond": bool(g["bc"])}
    notes = []
    if g["vc"] is None:
        if g["variant"]:
            raise ValueError("{!r}: a correction variant without 'VC'"
                             .format(name))
        kw["vc"] = None
    elif g["vc"] == "VC2":
        kw["vc"] = "VC2"
        own = "V4" if method == "PBG" else "V1"
        if g["variant"] not in (None, own):
            notes.append("VC2 {} uses the {} correction functions here, not "
                         "{}".format(method, own, g["variant"]))
    else:
        kw["vc"] = g["variant"] or ("V5" if g["bc"] and method == "PBG"
                                    else "V3")
    if g["boundary"]:
        if kw["vc"] is None:
            raise ValueError("{!r}: a boundary variant without 'VC'"
                             .format(name))
        kw["vc_boundary"] = g["boundary"]
    return kw, notes


def name_of(basis):
    """The thesis name of a :class:`~skfem_pg.FamilyBasis`."""
    vc = basis.vc
    prefix = ("VC2" if vc == "VC2" else "VC" if vc else "") + \
        ("BC" if basis.bond else "")
    method = {"PPG1": "PPG"}.get(basis.method, basis.method)
    form = {v: k for k, v in SHAPES.items()}[basis.shape]
    if vc == "VC2":
        variant = " V4" if basis.method == "PBG" else " V1"
    else:
        variant = " " + vc if vc else ""
    if vc and basis.vc_boundary != "min-norm":
        variant += basis.vc_boundary
    return "{}{}{} {}".format(prefix, method, variant, form)
