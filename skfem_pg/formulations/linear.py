"""Linear elasticity as a plain scikit-fem form that assembles on FE and
family bases alike (``skfem.helpers``, dimension agnostic)."""
import skfem as fem
from skfem.helpers import ddot, sym_grad, trace, eye

from ..materials.constants import check_moduli


def linear_elasticity(lam, mu):
    r""":math:`a(u, v) = \int (2\mu\,\varepsilon(u) + \lambda\,\mathrm{tr}
    \varepsilon(u) I) : \varepsilon(v)`."""
    lam, mu = check_moduli(lam=lam, mu=mu)

    @fem.BilinearForm
    def linear_elasticity(u, v, w):
        e = sym_grad(u)
        return ddot(2.0 * mu * e + lam * eye(trace(e), e.shape[0]),
                    sym_grad(v))
    return linear_elasticity
