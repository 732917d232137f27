// albedo.h: directional albedo of a reflectance model by adaptive quadrature on the CPU, for
// tests, documentation and the tables some models keep in their parameter block (coupled).
#pragma once
#include <cstdint>

#include "../../shaders/shared/layout.h"

namespace nusselt {

// Two independent quadratures: nested adaptive Gauss-Kronrod (7-15) over u = cos(theta_o) = s^2
// (s in [0, 1], removes the rim singularities of ward92/duer/minnaert/schlick/beard_maxwell) and
// the azimuth phi_o, with the peak (mirror direction) as a breakpoint of both. ThetaOuter
// integrates phi inside s; PhiOuter integrates s inside phi.
enum class AlbedoMethod { ThetaOuter, PhiOuter };

// a(wi) = integral over the hemisphere of luminance(f(wi, wo)) cos(theta_o) dw_o for
// wi = (sin t cos p, sin t sin p, cos t), t = thetaDeg, p = phiDeg. Relative accuracy ~1e-6
// for smooth lobes (tested to 1e-4 on the catalogue's hard sets).
double directionalAlbedo(std::uint32_t model, const shared::BrdfParams& params, double thetaDeg);
double directionalAlbedo(std::uint32_t model, const shared::BrdfParams& params, double thetaDeg, double phiDeg,
                         AlbedoMethod method = AlbedoMethod::ThetaOuter);

// Per channel (r, g, b) instead of the luminance.
void directionalAlbedoRgb(std::uint32_t model, const shared::BrdfParams& params, double thetaDeg, double phiDeg,
                          double out[3]);

// Fills the specular albedo tables of a coupled parameter block (COUPLED_TABLE1/2, COUPLED_ABAR1/2;
// see shaders/shared/brdf/coupled.h) from its m. Results are cached per m.
void fillCoupledTables(shared::BrdfParams& params);

}  // namespace nusselt
