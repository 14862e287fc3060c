// Gaussians projected for one camera as tega's rasterizer projects them
// (avatar/splat/include/tega/splat/gaussian_math.h): EWA splatting with the
// frustum clamp on J, the 0.3 px² low-pass, Mip-Splatting's opacity
// compensation when the run trained with it, the footprint where
// opacity·G ≥ 1/255, and the colour S·max(SH(dir) + 0.5, 0). Done here in
// double precision, once per view; the GPU only blends (renderer.js).

export const LOW_PASS = 0.3;
export const MIN_ALPHA = 1 / 255;
const NEAR = 0.01, FAR = 100, FRUSTUM_MARGIN = 0.15;
export const FLOATS_PER_SPLAT = 12;  // u, v, extent x, y | conic a, b, c, opacity | r, g, b, unused

// Basis functions of degree ≤ 3 at a unit direction, in 3DGS's order and signs.
function shBasis(degree, x, y, z, out) {
  out[0] = 0.28209479177387814;
  if (degree < 1) return;
  const c1 = 0.4886025119029199;
  out[1] = -c1 * y;
  out[2] = c1 * z;
  out[3] = -c1 * x;
  if (degree < 2) return;
  const xx = x * x, yy = y * y, zz = z * z, xy = x * y;
  out[4] = 1.0925484305920792 * xy;
  out[5] = -1.0925484305920792 * (y * z);
  out[6] = 0.31539156525252005 * (2 * zz - xx - yy);
  out[7] = -1.0925484305920792 * (x * z);
  out[8] = 0.5462742152960396 * (xx - yy);
  if (degree < 3) return;
  out[9] = -0.5900435899266435 * y * (3 * xx - yy);
  out[10] = 2.890611442640554 * xy * z;
  out[11] = -0.4570457994644658 * y * (4 * zz - xx - yy);
  out[12] = 0.3731763325901154 * z * (2 * zz - 3 * xx - 3 * yy);
  out[13] = -0.4570457994644658 * x * (4 * zz - xx - yy);
  out[14] = 1.445305721320277 * z * (xx - yy);
  out[15] = -0.5900435899266435 * x * (xx - 3 * yy);
}

// camera: {width, height, fx, fy, cx, cy, rotation: [9] row-major world-to-camera, translation: [3]}.
// Returns the splats back to front (for "over" blending), `count` of them.
export function projectSplats(fixed, frame, camera) {
  const n = frame.count;
  const R = camera.rotation, t = camera.translation;
  const { fx, fy, cx, cy, width, height } = camera;
  // Camera centre -Rᵀt, for the SH view direction.
  const centre = [0, 1, 2].map((c) => -(R[c] * t[0] + R[3 + c] * t[1] + R[6 + c] * t[2]));
  const limX = [(-0.5 - FRUSTUM_MARGIN * width - cx) / fx, (width - 0.5 + FRUSTUM_MARGIN * width - cx) / fx];
  const limY = [(-0.5 - FRUSTUM_MARGIN * height - cy) / fy, (height - 0.5 + FRUSTUM_MARGIN * height - cy) / fy];
  const splats = new Float64Array(FLOATS_PER_SPLAT * n);
  const depth = new Float64Array(n);
  const visible = [];
  const basis = new Float64Array(16);
  const K = fixed.coefficients;
  for (let g = 0; g < n; ++g) {
    const m = frame.means, o = 3 * g;
    const x = R[0] * m[o] + R[1] * m[o + 1] + R[2] * m[o + 2] + t[0];
    const y = R[3] * m[o] + R[4] * m[o + 1] + R[5] * m[o + 2] + t[1];
    const z = R[6] * m[o] + R[7] * m[o + 1] + R[8] * m[o + 2] + t[2];
    if (!(z >= NEAR && z <= FAR)) continue;
    const iz = 1 / z;
    const rx = Math.min(Math.max(x * iz, limX[0]), limX[1]);
    const ry = Math.min(Math.max(y * iz, limY[0]), limY[1]);
    const j0 = fx * iz, j2 = -fx * rx * iz, j4 = fy * iz, j5 = -fy * ry * iz;
    // Σ_cam = R Σ Rᵀ, then J Σ_cam Jᵀ.
    const c = frame.covariances, p = 6 * g;
    const S = [c[p], c[p + 1], c[p + 2], c[p + 1], c[p + 3], c[p + 4], c[p + 2], c[p + 4], c[p + 5]];
    const RS = new Array(9);
    for (let r = 0; r < 3; ++r)
      for (let k = 0; k < 3; ++k) RS[3 * r + k] = R[3 * r] * S[k] + R[3 * r + 1] * S[3 + k] + R[3 * r + 2] * S[6 + k];
    const C = new Array(9);
    for (let r = 0; r < 3; ++r)
      for (let k = 0; k < 3; ++k) C[3 * r + k] = RS[3 * r] * R[3 * k] + RS[3 * r + 1] * R[3 * k + 1] + RS[3 * r + 2] * R[3 * k + 2];
    const m0 = [j0 * C[0] + j2 * C[6], j0 * C[1] + j2 * C[7], j0 * C[2] + j2 * C[8]];
    const m1 = [j4 * C[3] + j5 * C[6], j4 * C[4] + j5 * C[7], j4 * C[5] + j5 * C[8]];
    const s00 = m0[0] * j0 + m0[2] * j2, s01 = m0[1] * j4 + m0[2] * j5, s11 = m1[1] * j4 + m1[2] * j5;
    const detRaw = s00 * s11 - s01 * s01;
    const detBlur = (s00 + LOW_PASS) * (s11 + LOW_PASS) - s01 * s01;
    if (!(detBlur > 0)) continue;
    const compensation = fixed.antialiased ? (detRaw > 0 ? Math.sqrt(detRaw / detBlur) : 0) : 1;
    const opacity = fixed.opacities[g] * compensation;
    if (!(opacity >= MIN_ALPHA)) continue;
    const u = fx * x * iz + cx, v = fy * y * iz + cy;
    const level = 2 * Math.log(opacity / MIN_ALPHA);
    const extX = Math.sqrt(level * (s00 + LOW_PASS)) + 0.01, extY = Math.sqrt(level * (s11 + LOW_PASS)) + 0.01;
    if (Math.max(Math.ceil(u - extX), 0) > Math.min(Math.floor(u + extX), width - 1)) continue;
    if (Math.max(Math.ceil(v - extY), 0) > Math.min(Math.floor(v + extY), height - 1)) continue;
    // Colour: S·max(SH(h, dir) + 0.5, 0), dir from the camera centre to the mean.
    const dx = m[o] - centre[0], dy = m[o + 1] - centre[1], dz = m[o + 2] - centre[2];
    const norm = Math.sqrt(dx * dx + dy * dy + dz * dz), inv = norm > 0 ? 1 / norm : 0;
    shBasis(fixed.shDegree, dx * inv, dy * inv, dz * inv, basis);
    const s = frame.shading[g], q = FLOATS_PER_SPLAT * g;
    for (let ch = 0; ch < 3; ++ch) {
      let sum = 0.5;
      for (let b = 0; b < K; ++b) sum += basis[b] * fixed.sh[(g * K + b) * 3 + ch];
      splats[q + 8 + ch] = s * Math.max(sum, 0);
    }
    splats[q] = u;
    splats[q + 1] = v;
    splats[q + 2] = extX;
    splats[q + 3] = extY;
    splats[q + 4] = (s11 + LOW_PASS) / detBlur;
    splats[q + 5] = -s01 / detBlur;
    splats[q + 6] = (s00 + LOW_PASS) / detBlur;
    splats[q + 7] = opacity;
    depth[g] = z;
    visible.push(g);
  }
  // Front to back by depth, ties in index order (as the rasterizer's stable
  // sort), then reversed: the GPU blends back to front.
  visible.sort((a, b) => depth[a] - depth[b] || a - b);
  const out = new Float32Array(FLOATS_PER_SPLAT * visible.length);
  for (let k = 0; k < visible.length; ++k) {
    const from = FLOATS_PER_SPLAT * visible[visible.length - 1 - k];
    out.set(splats.subarray(from, from + FLOATS_PER_SPLAT), FLOATS_PER_SPLAT * k);
  }
  return { data: out, count: visible.length };
}
