// Pinhole cameras in tega's convention (x_cam = R x_world + t, OpenCV axes:
// x right, y down, z forward) and an orbit about a target for the free view.

const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const scale = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const normalize = (a) => scale(a, 1 / Math.hypot(...a));

export function cameraCentre(camera) {
  const R = camera.rotation, t = camera.translation;
  return [0, 1, 2].map((c) => -(R[c] * t[0] + R[3 + c] * t[1] + R[6 + c] * t[2]));
}

// A camera at `position` looking at `target`, image y along -up as far as possible.
export function lookAt(position, target, up) {
  const z = normalize(sub(target, position));
  const x = normalize(cross(scale(up, -1), z));
  const y = cross(z, x);
  const rotation = [...x, ...y, ...z];
  const translation = [-dot(x, position), -dot(y, position), -dot(z, position)];
  return { rotation, translation };
}

// The intrinsics at another image size, pixel centres kept consistent: x' = s(x + 0.5) - 0.5.
export function resized(camera, width, height) {
  const sx = width / camera.width, sy = height / camera.height;
  return { ...camera, width, height, fx: camera.fx * sx, fy: camera.fy * sy,
           cx: sx * (camera.cx + 0.5) - 0.5, cy: sy * (camera.cy + 0.5) - 0.5 };
}

// Orbit (drag), pan (shift- or right-drag) and zoom (wheel) about a target.
export class Orbit {
  constructor(up) {
    this.up = normalize(up);
  }

  // Starts from a camera's position about `target`.
  placeAt(camera, target) {
    this.target = target;
    const offset = sub(cameraCentre(camera), target);
    this.distance = Math.hypot(...offset);
    const [e1, e2] = this.basis();
    const along = dot(offset, this.up);
    this.pitch = Math.asin(Math.max(-1, Math.min(1, along / this.distance)));
    this.yaw = Math.atan2(dot(offset, e2), dot(offset, e1));
  }

  // Two axes perpendicular to up.
  basis() {
    const helper = Math.abs(this.up[0]) < 0.9 ? [1, 0, 0] : [0, 1, 0];
    const e1 = normalize(cross(this.up, helper));
    return [e1, cross(this.up, e1)];
  }

  position() {
    const [e1, e2] = this.basis();
    const flat = add(scale(e1, Math.cos(this.yaw)), scale(e2, Math.sin(this.yaw)));
    const direction = add(scale(flat, Math.cos(this.pitch)), scale(this.up, Math.sin(this.pitch)));
    return add(this.target, scale(direction, this.distance));
  }

  pose() {
    return lookAt(this.position(), this.target, this.up);
  }

  rotate(dx, dy) {
    this.yaw -= dx * 0.005;
    this.pitch = Math.max(-1.5, Math.min(1.5, this.pitch + dy * 0.005));
  }

  pan(dx, dy, focal) {
    const { rotation: R } = this.pose();
    const perPixel = this.distance / focal;
    const right = [R[0], R[1], R[2]], down = [R[3], R[4], R[5]];
    this.target = add(this.target, add(scale(right, -dx * perPixel), scale(down, -dy * perPixel)));
  }

  zoom(factor) {
    this.distance *= factor;
  }
}
