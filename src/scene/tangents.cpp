// tangents.cpp: see tangents.h.
#include "scene/tangents.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace nusselt {

glm::vec3 perpendicularTo(const glm::vec3& n) {
  const float sign = std::copysign(1.0f, n.z);
  const float a = -1.0f / (sign + n.z);
  const float b = n.x * n.y * a;
  return glm::vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
}

glm::vec3 orthonormalTangent(const glm::vec3& t, const glm::vec3& n) {
  // n normalised in double: a float normal is unit only to ~1e-7, and for t (nearly) along n the
  // residue of a non-unit n would dominate o and leave it far from orthogonal. A tangent within
  // 1e-6 of the normal's direction has no usable part on the surface.
  const glm::dvec3 nd = glm::normalize(glm::dvec3(n)), td(t);
  glm::dvec3 o = td - nd * glm::dot(nd, td);
  double len = glm::length(o);
  if (!std::isfinite(len) || !(len > 1e-6 * glm::length(td))) return perpendicularTo(n);
  return glm::vec3(o / len);
}

namespace {

double cornerAngle(const glm::dvec3& a, const glm::dvec3& b) {
  double la = glm::length(a), lb = glm::length(b);
  if (!(la > 0) || !(lb > 0)) return 0.0;
  return std::acos(std::clamp(glm::dot(a, b) / (la * lb), -1.0, 1.0));
}

}  // namespace

std::size_t generateTangents(std::size_t triangles, const glm::vec3* positions, const glm::vec3* normals,
                             const glm::vec2* uvs, const std::uint32_t* vertexOfCorner, std::size_t vertexCount,
                             glm::vec4* tangentsOut) {
  struct Sum {
    glm::dvec3 t{0.0}, b{0.0};
  };
  // [2 v + 0]: triangles with r > 0 at vertex v; [2 v + 1]: r < 0.
  std::vector<Sum> sums(2 * vertexCount);
  std::vector<signed char> side(triangles, 0);  // +1, -1, or 0 for no usable gradient
  for (std::size_t t = 0; t < triangles; ++t) {
    const glm::dvec3 p0(positions[3 * t]), p1(positions[3 * t + 1]), p2(positions[3 * t + 2]);
    const glm::dvec2 w0(uvs[3 * t]), w1(uvs[3 * t + 1]), w2(uvs[3 * t + 2]);
    const glm::dvec3 e1 = p1 - p0, e2 = p2 - p0;
    const glm::dvec2 d1 = w1 - w0, d2 = w2 - w0;
    const double r = d1.x * d2.y - d2.x * d1.y;
    if (!std::isfinite(r) || r == 0.0) continue;
    glm::dvec3 tu = (e1 * d2.y - e2 * d1.y) / r;
    glm::dvec3 tv = (e2 * d1.x - e1 * d2.x) / r;
    const double lu = glm::length(tu), lv = glm::length(tv);
    if (!std::isfinite(lu) || !std::isfinite(lv) || !(lu > 0) || !(lv > 0)) continue;
    tu /= lu;
    tv /= lv;
    side[t] = r > 0 ? 1 : -1;
    const double angle[3] = {cornerAngle(e1, e2), cornerAngle(p2 - p1, p0 - p1), cornerAngle(p0 - p2, p1 - p2)};
    for (int k = 0; k < 3; ++k) {
      Sum& s = sums[2 * std::size_t(vertexOfCorner[3 * t + k]) + (r > 0 ? 0 : 1)];
      s.t += angle[k] * tu;
      s.b += angle[k] * tv;
    }
  }
  std::size_t fallbacks = 0;
  for (std::size_t t = 0; t < triangles; ++t) {
    for (int k = 0; k < 3; ++k) {
      const glm::vec3 n = normals[3 * t + k];
      glm::vec4& out = tangentsOut[3 * t + k];
      if (side[t] == 0) {
        out = glm::vec4(perpendicularTo(n), 1.0f);
        ++fallbacks;
        continue;
      }
      const Sum& s = sums[2 * std::size_t(vertexOfCorner[3 * t + k]) + (side[t] > 0 ? 0 : 1)];
      glm::vec3 tangent = orthonormalTangent(glm::vec3(s.t), n);
      float w = glm::dot(glm::cross(glm::dvec3(n), glm::dvec3(tangent)), s.b) < 0.0 ? -1.0f : 1.0f;
      out = glm::vec4(tangent, w);
    }
  }
  return fallbacks;
}

}  // namespace nusselt
