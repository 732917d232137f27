// tangents.h: tangent frames for normal mapping when a glTF primitive has no TANGENT.
//
// Debian 12 packages no MikkTSpace (glTF's reference algorithm), so this is the classic
// per-triangle tangent from texture-coordinate gradients (Lengyel), accumulated per vertex and
// orthonormalised against the shading normal; see docs/scenes.md for where it differs.
#pragma once
#include <cstddef>
#include <cstdint>

#include <glm/glm.hpp>

namespace nusselt {

// A unit vector perpendicular to the unit vector n, continuous except where n.z changes sign
// (Duff et al., "Building an Orthonormal Basis, Revisited", JCGT 6(1), 2017).
glm::vec3 perpendicularTo(const glm::vec3& n);

// Gram-Schmidt: the unit part of t orthogonal to the unit normal n, or perpendicularTo(n) when
// that part is zero or not finite.
glm::vec3 orthonormalTangent(const glm::vec3& t, const glm::vec3& n);

// Tangents for `triangles` triangles given per corner (three consecutive entries per
// triangle): world-space positions, unit shading normals, texture coordinates, and the index of
// the corner's vertex in its primitive (< vertexCount; corners with the same vertex share one
// accumulated tangent). For every triangle the tangent is the direction of increasing u,
//   T = (e1 dv2 - e2 dv1) / r,  B = (e2 du1 - e1 du2) / r,  r = du1 dv2 - du2 dv1,
// with e1, e2 the edges from corner 0 and (du, dv) the matching texture-coordinate differences.
// Unit T and B are summed per vertex weighted by the triangle's angle at that corner, in two
// separate sums for triangles of positive and of negative r, so that vertices on a mirrored
// texture seam keep one frame per side. Each corner then gets its sum orthonormalised against
// its normal, and w = -1 where the summed B points against cross(n, T). Corners of triangles
// whose texture coordinates have zero area (r = 0) or are not finite get perpendicularTo(n) and
// w = +1. Returns the number of such corners.
std::size_t generateTangents(std::size_t triangles, const glm::vec3* positions, const glm::vec3* normals,
                             const glm::vec2* uvs, const std::uint32_t* vertexOfCorner, std::size_t vertexCount,
                             glm::vec4* tangentsOut);

}  // namespace nusselt
