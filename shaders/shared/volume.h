// volume.h: Beer-Lambert absorption inside a refracting volume (KHR_materials_volume;
// docs/scenes.md, "Volumes"). The loader turns a material's attenuationColor c and
// attenuationDistance d into an absorption coefficient per channel (volumeAbsorption); the shade
// stage multiplies the throughput of a path segment travelled inside the volume by its
// transmittance (volumeTransmittance). Which segments lie inside: a ray that meets a triangle of
// an absorbing material from its back (against the geometric normal, which points out of a closed
// glTF volume) has travelled inside that material's volume since its previous vertex.
#ifndef NUSSELT_VOLUME_H
#define NUSSELT_VOLUME_H
#include "prelude.h"
SHARED_BEGIN

// The largest absorption coefficient [1/m] kept: a colour channel of 0 (or one so small that
// -ln c / d overflows) absorbs everything over any distance a float can tell from 0, without
// making inf * 0 = NaN when the distance is 0.
#define VOLUME_MAX_ABSORPTION 1e30f

// sigma_a = -ln(c) / d per channel [1/m], c in [0, 1], d > 0 (the loader rejects anything else);
// clamped to [0, VOLUME_MAX_ABSORPTION]. d = +inf (no attenuationDistance): 0, whatever c.
SHARED_FN float volumeAbsorption1(float c, float d) {
  if (!isFinite(d)) return 0.0f;
  if (!(c > 0.0f)) return VOLUME_MAX_ABSORPTION;
  float s = -log(min(c, 1.0f)) / d;
  return s >= 0.0f ? min(s, VOLUME_MAX_ABSORPTION) : 0.0f;
}

SHARED_FN vec3 volumeAbsorption(vec3 attenuationColor, float attenuationDistance) {
  return vec3(volumeAbsorption1(attenuationColor.x, attenuationDistance),
              volumeAbsorption1(attenuationColor.y, attenuationDistance),
              volumeAbsorption1(attenuationColor.z, attenuationDistance));
}

// exp(-sigma_a t) per channel: the fraction of radiance left after a distance t >= 0 inside.
SHARED_FN vec3 volumeTransmittance(vec3 sigma, float t) {
  return vec3(exp(-sigma.x * t), exp(-sigma.y * t), exp(-sigma.z * t));
}

SHARED_END
#endif
