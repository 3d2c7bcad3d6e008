"""Elastic constants: checks and conversions."""
import numpy as np


def check_moduli(**moduli):
    r"""Refuse non-physical elastic constants, naming them.

    Keywords ``E``, ``mu``, ``K`` (positive), ``nu`` (in (-1, 0.5)),
    ``lam`` (with ``mu``: the bulk modulus :math:`\lambda + 2\mu/3` must
    be positive).  Non-finite values are refused too.  Returns the values
    as floats, in the order given.
    """
    out = {}
    for name, value in moduli.items():
        try:
            v = float(value)
        except (TypeError, ValueError):
            raise ValueError("the elastic constant {} must be a number, got "
                             "{!r}".format(name, value)) from None
        if not np.isfinite(v):
            raise ValueError("the elastic constant {} must be finite, got {}"
                             .format(name, v))
        out[name] = v
    for name in ("E", "mu", "K"):
        if name in out and out[name] <= 0:
            what = {"E": "Young's modulus E", "mu": "the shear modulus mu",
                    "K": "the bulk modulus K"}[name]
            raise ValueError("{} must be positive, got {}".format(
                what, out[name]))
    if "nu" in out:
        nu = out["nu"]
        if nu == 0.5:
            raise ValueError(
                "Poisson's ratio nu = 0.5 is incompressible (lambda is "
                "infinite): use nu < 0.5 with a locking-free formulation "
                "(FE Q1P0 / H1P0 today; the incompressible PG formulations, "
                "IUnlP0, are not built yet)")
        if not -1.0 < nu < 0.5:
            raise ValueError("Poisson's ratio nu must lie in (-1, 0.5), got "
                             "{}".format(nu))
    if "lam" in out and "mu" in out \
            and out["lam"] + 2.0 * out["mu"] / 3.0 <= 0:
        raise ValueError(
            "lambda = {} and mu = {} give a bulk modulus lambda + 2 mu / 3 "
            "= {} <= 0 (Poisson's ratio <= -1)".format(
                out["lam"], out["mu"], out["lam"] + 2.0 * out["mu"] / 3.0))
    return tuple(out.values())


def lame(E, nu, plane_stress=False):
    r"""Lamé parameters :math:`(\lambda, \mu)`; with ``plane_stress`` the
    effective :math:`\lambda^* = 2\lambda\mu/(\lambda + 2\mu)`.
    ``E > 0`` and ``-1 < nu < 0.5`` (:func:`check_moduli`)."""
    E, nu = check_moduli(E=E, nu=nu)
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    mu = E / (2 * (1 + nu))
    if plane_stress:
        lam = 2 * lam * mu / (lam + 2 * mu)
    return lam, mu


def check_finite(owner, **values):
    """The ``values`` as floats, in the order given; a value that is not a
    finite number raises ``ValueError`` naming it and ``owner`` (the law
    whose parameter it is)."""
    out = []
    for name, value in values.items():
        try:
            v = float(value)
        except (TypeError, ValueError):
            v = np.nan
        if not np.isfinite(v):
            raise ValueError("{}: {} must be a finite number, got {!r}"
                             .format(owner, name, value))
        out.append(v)
    return out
