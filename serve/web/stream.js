// Decoders of tega serve's frame stream (docs/render-eval-export.md#frame-stream);
// serve/src/frame_stream.cpp writes it. Little-endian throughout.

const STATIC_MAGIC = 'TGSS';
const FRAME_MAGIC = 'TGSF';
const VERSION = 1;

function checkHeader(view, magic, headerBytes, what) {
  if (view.byteLength < headerBytes) throw new Error(`${what}: ${view.byteLength} bytes, shorter than its header`);
  const found = String.fromCharCode(view.getUint8(0), view.getUint8(1), view.getUint8(2), view.getUint8(3));
  if (found !== magic) throw new Error(`${what}: not a tega frame stream (magic ${magic} expected)`);
  const version = view.getUint32(4, true);
  if (version !== VERSION) throw new Error(`${what}: stream version ${version}, this page reads ${VERSION}`);
}

// What no frame changes: opacities and the SH coefficients without the shading.
export function decodeStatic(buffer, what = 'static part') {
  const view = new DataView(buffer);
  checkHeader(view, STATIC_MAGIC, 28, what);
  const count = view.getUint32(8, true);
  const shDegree = view.getUint8(12);
  const coefficients = (shDegree + 1) * (shDegree + 1);
  const expected = 28 + 4 * (count + count * coefficients * 3);
  if (buffer.byteLength !== expected) throw new Error(`${what}: ${buffer.byteLength} bytes where its header says ${expected}`);
  return {
    count,
    shDegree,
    coefficients,
    antialiased: (view.getUint8(13) & 1) !== 0,
    background: [view.getFloat32(16, true), view.getFloat32(20, true), view.getFloat32(24, true)],
    opacities: new Float32Array(buffer, 28, count),
    sh: new Float32Array(buffer, 28 + 4 * count, count * coefficients * 3),
  };
}

function dequantiser(lo, hi, steps) {
  const step = (hi - lo) / steps;
  return (code) => lo + code * step;
}

// One frame: world means, covariances Σ = R diag(σ²) Rᵀ (xx, xy, xz, yy, yz, zz)
// and the shading S of every Gaussian.
export function decodeFrame(buffer, what = 'frame') {
  const view = new DataView(buffer);
  checkHeader(view, FRAME_MAGIC, 52, what);
  const n = view.getUint32(8, true);
  const expected = 52 + 14 * n;
  if (buffer.byteLength !== expected) throw new Error(`${what}: ${buffer.byteLength} bytes where its header says ${expected}`);
  const f32 = (offset) => view.getFloat32(offset, true);
  const position = [0, 1, 2].map((a) => dequantiser(f32(12 + 4 * a), f32(24 + 4 * a), 65535));
  const logScale = dequantiser(f32(36), f32(40), 255);
  const shade = dequantiser(f32(44), f32(48), 255);
  const rotations = 52, positions = rotations + 4 * n, scales = positions + 6 * n, shades = scales + 3 * n;
  const means = new Float64Array(3 * n), covariances = new Float64Array(6 * n), shading = new Float64Array(n);
  const q = [0, 0, 0, 0];
  for (let i = 0; i < n; ++i) {
    for (let a = 0; a < 3; ++a) means[3 * i + a] = position[a](view.getUint16(positions + 2 * (3 * i + a), true));
    // Smallest three: the largest component left out, the others 10 bits each in ±1/√2.
    const packed = view.getUint32(rotations + 4 * i, true);
    const largest = packed >>> 30;
    let sum = 0, shift = 20;
    for (let k = 0; k < 4; ++k) {
      if (k === largest) continue;
      q[k] = (((packed >>> shift) & 1023) / 1023 * 2 - 1) / Math.SQRT2;
      sum += q[k] * q[k];
      shift -= 10;
    }
    q[largest] = Math.sqrt(Math.max(0, 1 - sum));
    const v = [0, 1, 2].map((a) => Math.exp(2 * logScale(view.getUint8(scales + 3 * i + a))));
    setCovariance(covariances, 6 * i, q, v);
    shading[i] = shade(view.getUint8(shades + i));
  }
  return { count: n, means, covariances, shading };
}

// R diag(v) Rᵀ from a unit quaternion (w, x, y, z), packed as 6 values.
export function setCovariance(out, offset, [w, x, y, z], v) {
  const r = [
    1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
    2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
    2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y),
  ];
  const entry = (i, j) => r[3 * i] * v[0] * r[3 * j] + r[3 * i + 1] * v[1] * r[3 * j + 1] + r[3 * i + 2] * v[2] * r[3 * j + 2];
  out[offset] = entry(0, 0);
  out[offset + 1] = entry(0, 1);
  out[offset + 2] = entry(0, 2);
  out[offset + 3] = entry(1, 1);
  out[offset + 4] = entry(1, 2);
  out[offset + 5] = entry(2, 2);
}
