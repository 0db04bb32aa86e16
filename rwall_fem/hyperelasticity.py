"""Large deformation (total Lagrangian): the hyperelastic laws and their stable step.

Selected by ``material.model = "saint_venant_kirchhoff"`` or ``"neo_hookean"``
(compressible). The element kernels compute the internal force
f = int P(F) : grad(w) dX, F = I + grad(u), and the strain energy int psi(F) dX;
:func:`strain_energy_density` is the same law in UFL, the reference the tests
compare the kernels against and the field output's stress. At u = 0 both models
have the small-strain stiffness, so the initial stable step is that of the linear
model; the kernels re-estimate it at every step from the law's acoustic tensor at the
current strain (``kernels/materials.h``, :mod:`rwall_fem.time_step`).
"""

from __future__ import annotations

import ufl

from rwall_fem.scene import Material

__all__ = ["strain_energy_density"]


def strain_energy_density(F, material: Material):
    """psi(F) in J/m^3 for the material's hyperelastic model."""
    lmbda, mu = material.lame
    d = F.ufl_shape[0]
    if material.model == "saint_venant_kirchhoff":
        E = 0.5 * (F.T * F - ufl.Identity(d))
        return 0.5 * lmbda * ufl.tr(E) ** 2 + mu * ufl.inner(E, E)
    if material.model == "neo_hookean":
        J = ufl.det(F)
        return 0.5 * mu * (ufl.tr(F.T * F) - d) - mu * ufl.ln(J) + 0.5 * lmbda * ufl.ln(J) ** 2
    raise ValueError(f"no hyperelastic model {material.model!r}")
