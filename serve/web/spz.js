// Niantic's SPZ (version 2) as `tega export --format spz` writes it
// (docs/render-eval-export.md#spz; avatar/tools/src/gaussian_spz.cpp reads it
// the same way): a gzip stream of a 16-byte header and, for all Gaussians in
// turn, 24-bit fixed-point positions, 8-bit opacities, DC colours, log scales,
// rotations (x, y, z; w ≥ 0) and higher SH coefficients. SPZ's frame is
// right-up-back; tega's, whose cameras the page uses, right-down-front: a half
// turn about x apart.

import { setCovariance } from './stream.js';

const MAGIC = 0x5053474e;  // "NGSP"
const COLOR_SCALE = 0.15;
const OPACITY_FLOOR = 0.5 / 255;
// Sign of each higher SH coefficient under the half turn (y -> -y, z -> -z), in 3DGS's order.
const HALF_TURN_SH_SIGN = [-1, -1, 1, -1, 1, 1, -1, 1, -1, 1, -1, -1, 1, -1, 1];

async function gunzip(bytes) {
  const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream('gzip'));
  return new Response(stream).arrayBuffer();
}

// The file as the page's static part and one frame (shading 1: SPZ colours are baked).
export async function decodeSpz(gzipped, background, what = 'SPZ file') {
  let buffer;
  try {
    buffer = await gunzip(gzipped);
  } catch (error) {
    throw new Error(`${what}: not a gzip stream (${error})`);
  }
  const view = new DataView(buffer);
  if (buffer.byteLength < 16 || view.getUint32(0, true) !== MAGIC) throw new Error(`${what}: not an SPZ file`);
  const version = view.getUint32(4, true);
  if (version !== 2) throw new Error(`${what}: SPZ version ${version}; the page reads version 2`);
  const n = view.getUint32(8, true), degree = view.getUint8(12), fractionalBits = view.getUint8(13);
  const flags = view.getUint8(14);
  if (degree > 3 || (flags & 2)) throw new Error(`${what}: SH degree ${degree} or extensions the page does not read`);
  const coefficients = (degree + 1) * (degree + 1), higher = coefficients - 1;
  const positions = 16, alphas = positions + 9 * n, colors = alphas + n, scales = colors + 3 * n;
  const rotations = scales + 3 * n, shs = rotations + 3 * n;
  if (buffer.byteLength !== shs + 3 * higher * n)
    throw new Error(`${what}: ${buffer.byteLength} bytes where its header says ${shs + 3 * higher * n}`);
  const bytes = new Uint8Array(buffer);
  const step = 1 / (1 << fractionalBits);
  const means = new Float64Array(3 * n), covariances = new Float64Array(6 * n);
  const opacities = new Float32Array(n), sh = new Float32Array(n * coefficients * 3);
  const turn = [1, -1, -1];
  for (let i = 0; i < n; ++i) {
    for (let a = 0; a < 3; ++a) {
      const b = positions + 3 * (3 * i + a);
      let fixed = bytes[b] | (bytes[b + 1] << 8) | (bytes[b + 2] << 16);
      if (fixed & 0x800000) fixed -= 1 << 24;
      means[3 * i + a] = turn[a] * fixed * step;
    }
    opacities[i] = Math.min(Math.max(bytes[alphas + i] / 255, OPACITY_FLOOR), 1 - OPACITY_FLOOR);
    for (let ch = 0; ch < 3; ++ch) sh[i * coefficients * 3 + ch] = (bytes[colors + 3 * i + ch] / 255 - 0.5) / COLOR_SCALE;
    for (let j = 0; j < higher; ++j)
      for (let ch = 0; ch < 3; ++ch)
        sh[(i * coefficients + 1 + j) * 3 + ch] = HALF_TURN_SH_SIGN[j] * (bytes[shs + 3 * (higher * i + j) + ch] - 128) / 128;
    const xyz = [0, 1, 2].map((k) => bytes[rotations + 3 * i + k] / 127.5 - 1);
    const squared = xyz[0] * xyz[0] + xyz[1] * xyz[1] + xyz[2] * xyz[2];
    const shrink = squared > 1 ? 1 / Math.sqrt(squared) : 1;
    // (w, x, y, z) of D R D, D = diag(1, -1, -1): y and z change sign.
    const q = [Math.sqrt(Math.max(0, 1 - squared)), xyz[0] * shrink, -xyz[1] * shrink, -xyz[2] * shrink];
    const variances = [0, 1, 2].map((k) => Math.exp(2 * (bytes[scales + 3 * i + k] / 16 - 10)));
    setCovariance(covariances, 6 * i, q, variances);
  }
  return {
    fixed: { count: n, shDegree: degree, coefficients, antialiased: (flags & 1) !== 0, background, opacities, sh },
    frame: { count: n, means, covariances, shading: new Float64Array(n).fill(1) },
  };
}
