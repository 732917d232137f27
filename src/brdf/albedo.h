// albedo.h: directional albedo of a reflectance model by adaptive quadrature on the CPU, for
// tests, documentation and the tables some models keep in their parameter block (coupled).
#pragma once
#include <cstdint>
#include <functional>

#include "../../shaders/shared/layout.h"

namespace nusselt {

// Two independent quadratures: nested adaptive Gauss-Kronrod (7-15) over t with
// u = cos(theta_o) = sin^2(pi t / 2) (t in [0, 1]; u ~ t^2 at the rim removes the rim
// singularities of ward92/duer/minnaert/schlick/beard_maxwell, and t is regular at the pole) and
// the azimuth phi_o, with breakpoints graded towards the peak (mirror direction), the pole and the
// axes (anisotropic sheets). ThetaOuter integrates phi inside t; PhiOuter t inside phi.
enum class AlbedoMethod { ThetaOuter, PhiOuter };

// a(wi) = integral over the hemisphere of luminance(f(wi, wo)) cos(theta_o) dw_o for
// wi = (sin t cos p, sin t sin p, cos t), t = thetaDeg, p = phiDeg. Relative accuracy ~1e-6
// for smooth lobes (tested to 1e-4 on the catalogue's hard sets).
double directionalAlbedo(std::uint32_t model, const shared::BrdfParams& params, double thetaDeg);
double directionalAlbedo(std::uint32_t model, const shared::BrdfParams& params, double thetaDeg, double phiDeg,
                         AlbedoMethod method = AlbedoMethod::ThetaOuter);

// The same nested adaptive quadrature for any integrand: integral over the hemisphere of
// g(w) cos(theta_w) dw, with breakpoints graded towards the mirror direction of
// (sin t cos p, sin t sin p, cos t), t = thetaDeg, p = phiDeg, the pole and the axes.
// (Samplers fix the second argument of f and draw the first: the albedo in their convention is
// hemisphereIntegral(w -> lum f(w, v), theta_v), which differs from directionalAlbedo for models
// that are not reciprocal, such as strauss.)
double hemisphereIntegral(const std::function<double(shared::vec3)>& g, double thetaDeg, double phiDeg,
                          double relTol = 1e-6);

// Per channel (r, g, b) instead of the luminance.
void directionalAlbedoRgb(std::uint32_t model, const shared::BrdfParams& params, double thetaDeg, double phiDeg,
                          double out[3]);

// Fills the specular albedo tables of a coupled parameter block (COUPLED_TABLE1/2, COUPLED_ABAR1/2;
// see shaders/shared/brdf/coupled.h) from its m. Results are cached per m.
void fillCoupledTables(shared::BrdfParams& params);

}  // namespace nusselt
