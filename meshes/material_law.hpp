#pragma once
// The hyperelastic laws of kerf's materials: one name for the scene reader, the reference's
// material regions and every model that reads a material (the fast models read E and ν only).

namespace kerf {

/// The hyperelastic law the reference solves with (the fast models read E and ν only).
/// - neo_hookean: ψ = μ/2 (I₁ − 3) − μ ln J + λ/2 (ln J)² (Bonet & Wood 2008, eq. 6.28). Its
///   volumetric part is not convex: the pressure λ ln J / J peaks at J = e, so under strong
///   hydrostatic tension the material softens and the problem loses its mesh-independent solution.
/// - decoupled_neo_hookean: ψ = μ/2 (Ī₁ − 3) + κ/4 (J² − 1 − 2 ln J), κ = λ + 2μ/3 (Simo & Taylor
///   1991; deal.II step-44). Polyconvex with a convex volumetric part, so the problem stays
///   well posed at any stretch (Ball 1977); the same E and ν at small strain.
/// - st_venant_kirchhoff: ψ = λ/2 (tr E)² + μ E:E.
enum class MaterialLaw { neo_hookean, decoupled_neo_hookean, st_venant_kirchhoff };

} // namespace kerf
