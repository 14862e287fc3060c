#pragma once
// Per-point math of uvd_to_world's fused evaluation (fused_uvd_map.h), shared
// by the CPU loops and the CUDA kernels. For a point (u, v, d) in triangle t
// (uvd_map.h has the definitions):
//   b = (1 − b1 − b2, b1, b2),  (b1, b2) = inverse_t ((u,v) − corner0_t)
//   P = Σ bₖ vₖ,  m = Σ bₖ nₖ,  L = max(|m|, kMinNormalLength),  n = m/L
//   xyz = P + d n,  J_a = ∂P/∂a + d (∂m/∂a − n (n·∂m/∂a))/L  (a = u, v),  J_d = n
// with ∂b/∂(u,v) from the lookup's barycentric_gradient table. Backward
// reaches u, v, d only (the mesh is constant): with gₙ and g_L the gradients
// reaching n and L through xyz and J,
//   ∂L/∂m = gₙ/L + [|m| ≥ kMinNormalLength] (g_L − gₙ·n/L) n,
//   ∂L/∂bₖ = ∂L/∂xyz·vₖ + ∂L/∂m·nₖ,  ∂L/∂(u,v) = Σ ∂L/∂bₖ ∂bₖ/∂(u,v).

#include <cstdint>

#include "scalar_math.h"
#include "tega/core/host_device.h"

namespace tega::uvd::fused_uvd_map {

// Guards the normal's normalisation where the corner normals cancel out
// (never on a sane mesh: it needs normals flipping across one triangle).
constexpr double kMinNormalLength = 1e-12;

// The posed mesh and the lookup's per-triangle tables, contiguous.
template <typename T>
struct Surface {
  const int64_t* faces = nullptr;  // [F,3] vertex indices
  const T* vertices = nullptr;     // [V,3]
  const T* normals = nullptr;      // [V,3] unit vertex normals
  const T* corners = nullptr;      // [F,3,2] uv of the corners
  const T* inverse = nullptr;      // [F,2,2] (u,v) - corner 0 -> (b1,b2)
  const T* gradient = nullptr;     // [F,3,2] ∂b/∂(u,v)
};

// Everything F and J_F need at one point.
template <typename T>
struct Local {
  T b[3];          // barycentrics
  T db[3][2];      // ∂bₖ/∂(u,v)
  T v[3][3];       // corner positions [corner][xyz]
  T nv[3][3];      // corner normals
  T m[3];          // interpolated normal
  T length;        // L
  bool clamped;    // |m| < kMinNormalLength
  T n[3];          // m/L
  T dposition[3][2];  // ∂P/∂(u,v) [xyz][axis]
  T dm[3][2];         // ∂m/∂(u,v)
  T dn[3][2];         // ∂n/∂(u,v)
};

template <typename T>
TEGA_HD void evaluate(const Surface<T>& s, int64_t triangle, T u, T v, Local<T>& p) {
  const int64_t* face = s.faces + 3 * triangle;
  const T* corner0 = s.corners + 6 * triangle;
  const T* inverse = s.inverse + 4 * triangle;
  const T* gradient = s.gradient + 6 * triangle;
  const T du = u - corner0[0], dv = v - corner0[1];
  const T b1 = inverse[0] * du + inverse[1] * dv, b2 = inverse[2] * du + inverse[3] * dv;
  p.b[0] = T(1) - (b1 + b2);
  p.b[1] = b1;
  p.b[2] = b2;
  TEGA_UNROLL
  for (int k = 0; k < 3; ++k) {
    const int64_t vertex = face[k];
    TEGA_UNROLL
    for (int x = 0; x < 3; ++x) {
      p.v[k][x] = s.vertices[3 * vertex + x];
      p.nv[k][x] = s.normals[3 * vertex + x];
    }
    p.db[k][0] = gradient[2 * k];
    p.db[k][1] = gradient[2 * k + 1];
  }
  T length2 = T(0);
  TEGA_UNROLL
  for (int x = 0; x < 3; ++x) {
    p.m[x] = p.b[0] * p.nv[0][x] + p.b[1] * p.nv[1][x] + p.b[2] * p.nv[2][x];
    length2 += p.m[x] * p.m[x];
  }
  const T length = math_sqrt(length2);
  p.clamped = length < T(kMinNormalLength);
  p.length = p.clamped ? T(kMinNormalLength) : length;
  TEGA_UNROLL
  for (int x = 0; x < 3; ++x) p.n[x] = p.m[x] / p.length;
  TEGA_UNROLL
  for (int a = 0; a < 2; ++a) {
    T along_n = T(0);
    TEGA_UNROLL
    for (int x = 0; x < 3; ++x) {
      p.dposition[x][a] = p.v[0][x] * p.db[0][a] + p.v[1][x] * p.db[1][a] + p.v[2][x] * p.db[2][a];
      p.dm[x][a] = p.nv[0][x] * p.db[0][a] + p.nv[1][x] * p.db[1][a] + p.nv[2][x] * p.db[2][a];
      along_n += p.n[x] * p.dm[x][a];
    }
    TEGA_UNROLL
    for (int x = 0; x < 3; ++x) p.dn[x][a] = (p.dm[x][a] - p.n[x] * along_n) / p.length;
  }
}

// uv: the point's (u,v) [2]; xyz [3]; jacobian [3,3] row-major.
template <typename T>
TEGA_HD void forward_element(const Surface<T>& s, int64_t triangle, const T* uv, T d, T* xyz, T* jacobian) {
  Local<T> p;
  evaluate(s, triangle, uv[0], uv[1], p);
  TEGA_UNROLL
  for (int x = 0; x < 3; ++x) {
    const T position = p.b[0] * p.v[0][x] + p.b[1] * p.v[1][x] + p.b[2] * p.v[2][x];
    xyz[x] = position + d * p.n[x];
    jacobian[3 * x] = p.dposition[x][0] + d * p.dn[x][0];
    jacobian[3 * x + 1] = p.dposition[x][1] + d * p.dn[x][1];
    jacobian[3 * x + 2] = p.n[x];
  }
}

// grad_xyz [3] and grad_jacobian [3,3] may be null (no gradient reached
// them); writes grad_uvd [3].
template <typename T>
TEGA_HD void backward_element(const Surface<T>& s, int64_t triangle, const T* uv, T d, const T* grad_xyz,
                              const T* grad_jacobian, T* grad_uvd) {
  Local<T> p;
  evaluate(s, triangle, uv[0], uv[1], p);
  T grad_n[3] = {T(0), T(0), T(0)}, grad_b[3] = {T(0), T(0), T(0)};
  T grad_d = T(0), grad_length = T(0);
  if (grad_xyz) {
    TEGA_UNROLL
    for (int x = 0; x < 3; ++x) {
      grad_d += grad_xyz[x] * p.n[x];
      grad_n[x] += d * grad_xyz[x];
    }
    TEGA_UNROLL
    for (int k = 0; k < 3; ++k)
      grad_b[k] += grad_xyz[0] * p.v[k][0] + grad_xyz[1] * p.v[k][1] + grad_xyz[2] * p.v[k][2];
  }
  if (grad_jacobian) {
    TEGA_UNROLL
    for (int a = 0; a < 2; ++a) {
      // dn_a = (dm_a − n (n·dm_a))/L, reached with d ∂L/∂J_a.
      T along_n = T(0), grad_along_n = T(0), grad_dn_dot_dn = T(0);
      T grad_dn[3];
      TEGA_UNROLL
      for (int x = 0; x < 3; ++x) {
        grad_dn[x] = d * grad_jacobian[3 * x + a];
        grad_d += grad_jacobian[3 * x + a] * p.dn[x][a];
        along_n += p.n[x] * p.dm[x][a];
        grad_along_n += grad_dn[x] * p.n[x];
        grad_dn_dot_dn += grad_dn[x] * p.dn[x][a];
      }
      TEGA_UNROLL
      for (int x = 0; x < 3; ++x) grad_n[x] -= (along_n * grad_dn[x] + grad_along_n * p.dm[x][a]) / p.length;
      grad_length -= grad_dn_dot_dn / p.length;
    }
    TEGA_UNROLL
    for (int x = 0; x < 3; ++x) grad_n[x] += grad_jacobian[3 * x + 2];
  }
  // n = m/L, and L = |m| unless clamped.
  const T grad_n_dot_n = grad_n[0] * p.n[0] + grad_n[1] * p.n[1] + grad_n[2] * p.n[2];
  const T radial = p.clamped ? T(0) : grad_length - grad_n_dot_n / p.length;
  T grad_m[3];
  TEGA_UNROLL
  for (int x = 0; x < 3; ++x) grad_m[x] = grad_n[x] / p.length + radial * p.n[x];
  TEGA_UNROLL
  for (int k = 0; k < 3; ++k) grad_b[k] += grad_m[0] * p.nv[k][0] + grad_m[1] * p.nv[k][1] + grad_m[2] * p.nv[k][2];
  TEGA_UNROLL
  for (int a = 0; a < 2; ++a) grad_uvd[a] = grad_b[0] * p.db[0][a] + grad_b[1] * p.db[1][a] + grad_b[2] * p.db[2][a];
  grad_uvd[2] = grad_d;
}

}  // namespace tega::uvd::fused_uvd_map
