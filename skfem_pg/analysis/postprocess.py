r"""Particle fields for output: deformation gradient, Cauchy stress and
von Mises stress at every particle.

The particle value is the master evaluation of its own family,
:math:`F^{kk}` (:meth:`~skfem_pg.FamilyBasis.master_gradients`).
Stresses come from the material evaluated in 3-D; in 2-D,
``F`` is embedded with :math:`F_{33} = 1` (plane strain), so
:math:`\sigma_{33}` enters the von Mises stress
:math:`\sqrt{\tfrac32\, s:s}`, :math:`s = \sigma - \tfrac13\mathrm{tr}\sigma`.
"""
import numpy as np


def _embed3(F):
    d = F.shape[0]
    if d == 3:
        return F
    F3 = np.zeros((3, 3) + F.shape[2:])
    F3[:d, :d] = F
    F3[2, 2] = 1.0
    return F3


def cauchy_and_von_mises(material, F):
    r"""Cauchy stress ``(3, 3, ...)`` and von Mises stress ``(...)`` for
    deformation gradients ``F`` (``(d, d, ...)``): :math:`PF^T/J`, or the
    material's stress itself for a small-strain law
    (``material.small_strain``, :class:`~skfem_pg.materials.LinearElastic`;
    with its ``plane_stress``, :math:`\sigma_{zz} = 0` in 2-D)."""
    F3 = _embed3(F)
    P = material.stress(F3)
    if getattr(material, "small_strain", False):
        sigma = P.copy()
        if F.shape[0] == 2 and getattr(material, "plane_stress", False):
            sigma[2, 2] = 0.0  # the embedding's F_zz = 1 is plane strain
    else:
        J = np.linalg.det(np.moveaxis(F3, (0, 1), (-2, -1)))
        sigma = np.einsum("iK...,jK...->ij...", P, F3) / J
    s = sigma - np.trace(sigma) / 3.0 * np.eye(3).reshape(
        (3, 3) + (1,) * (sigma.ndim - 2))
    return sigma, np.sqrt(1.5 * np.einsum("ij...,ij...->...", s, s))


def particle_fields(basis, material, u):
    """``{"displacement", "F", "cauchy", "von_mises"}`` per particle of a
    vector :class:`~skfem_pg.FamilyBasis` (inactive particles: zeros),
    shapes ``(n, d)``, ``(n, 9)``, ``(n, 9)``, ``(n,)``; the tensors are
    3×3 (plane strain in 2-D: :math:`F_{zz} = 1`), as ParaView reads
    them."""
    p = basis.particles
    n, d = p.n, p.dim
    U = np.asarray(u, dtype=float).reshape(n, d)
    mem, _ = basis.families.padded()
    F = np.einsum("kia,kib->abk", U[mem], basis.master_gradients()) \
        + np.eye(d)[:, :, None]
    sigma, vm = cauchy_and_von_mises(material, F)
    masters = basis.families.masters
    out = {"displacement": u.reshape(n, d),
           "F": np.zeros((n, 9)), "cauchy": np.zeros((n, 9)),
           "von_mises": np.zeros(n)}
    out["F"][masters] = np.moveaxis(_embed3(F), -1, 0).reshape(-1, 9)
    out["cauchy"][masters] = np.moveaxis(sigma, -1, 0).reshape(-1, 9)
    out["von_mises"][masters] = vm
    return out
