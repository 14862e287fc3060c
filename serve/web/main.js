// The player: a run's takes played or scrubbed at the capture's frame rate,
// seen from the dataset's cameras (with the captured image beside the
// render) or a free orbit, with the run's eval numbers and the page's own
// frame rate.
//
// ?run=ID&frame=ID&camera=NAME&still=1 renders one frame from one dataset
// camera at its image size and stops. Still mode loads synchronously, so
// the page is finished when its load event fires, which is when headless
// Chromium's --dump-dom and --screenshot read it; it then leaves the render
// as a PNG data URL in #still-png and its frame rate in #render-fps.
// &take_load=1 also loads every frame of the frame's take and reports how
// long that took in #take-load-ms.
//
// ?splat=NAME&camera=NAME shows an SPZ file served with `tega serve --splat`
// from a dataset camera of the run (its render in #still-png with &still=1).

import { Orbit, cameraCentre, resized } from './camera.js';
import { projectSplats } from './projection.js';
import { SplatRenderer } from './renderer.js';
import { decodeSpz } from './spz.js';
import { decodeFrame, decodeStatic } from './stream.js';

const params = new URLSearchParams(location.search);
const still = params.get('still') === '1';
const $ = (id) => document.getElementById(id);

function fetchSync(url, binary) {
  const request = new XMLHttpRequest();
  request.open('GET', url, false);
  if (binary) request.overrideMimeType('text/plain; charset=x-user-defined');
  request.send();
  if (request.status !== 200) throw new Error(`${url}: ${request.status} ${request.responseText}`);
  if (!binary) return JSON.parse(request.responseText);
  const text = request.responseText, bytes = new Uint8Array(text.length);
  for (let i = 0; i < text.length; ++i) bytes[i] = text.charCodeAt(i) & 0xff;
  return bytes.buffer;
}

async function fetchAsync(url, binary) {
  const response = await fetch(url);
  if (!response.ok) throw new Error(`${url}: ${response.status} ${await response.text()}`);
  return binary ? response.arrayBuffer() : response.json();
}

const load = (url, binary) => (still ? fetchSync(url, binary) : fetchAsync(url, binary));
const urlOf = (template, fields) => template.replace(/\{(\w+)\}/g, (_, key) => encodeURIComponent(fields[key]));

class Player {
  constructor() {
    this.renderer = new SplatRenderer($('render'));
    this.frames = new Map();  // id -> decoded frame, or a promise of it
    this.drawTimes = [];
    this.playing = false;
  }

  // Resolves (or in still mode returns) once the run is loaded.
  openRun(run) {
    const finish = (index, fixed) => {
      this.index = index;
      this.fixed = decodeStatic(fixed, index.urls.static);
      this.frames.clear();
      this.takes = index.takes;
      this.cameras = index.cameras;
      const up = [0, 0, 0];
      for (const c of this.cameras) for (let k = 0; k < 3; ++k) up[k] -= c.rotation[3 + k] / this.cameras.length;
      this.orbit = new Orbit(up);
      this.showRunDetails();
    };
    const indexUrl = `/api/runs/${encodeURIComponent(run)}/index.json`;
    if (still) {
      const index = fetchSync(indexUrl, false);
      return finish(index, fetchSync(index.urls.static, true));
    }
    return fetchAsync(indexUrl, false).then(async (index) => finish(index, await fetchAsync(index.urls.static, true)));
  }

  frameUrl(id) {
    return urlOf(this.index.urls.frame, { frame: id });
  }

  frameSync(id) {
    if (!(this.frames.get(id) && !(this.frames.get(id) instanceof Promise)))
      this.frames.set(id, decodeFrame(fetchSync(this.frameUrl(id), true), this.frameUrl(id)));
    return this.frames.get(id);
  }

  frameAsync(id) {
    if (!this.frames.has(id)) {
      const pending = fetchAsync(this.frameUrl(id), true).then((bytes) => {
        const frame = decodeFrame(bytes, this.frameUrl(id));
        this.frames.set(id, frame);
        return frame;
      });
      this.frames.set(id, pending);
    }
    return Promise.resolve(this.frames.get(id));
  }

  // The camera to render from: a dataset camera, or the orbit with its intrinsics.
  viewCamera(frame) {
    const base = this.cameras.find((c) => c.name === this.cameraName) || this.cameras[0];
    if (still) return base;
    const width = Math.min($('view').clientWidth || base.width, 960);
    const height = Math.round(width * base.height / base.width);
    if (this.cameraName !== 'free') return resized(base, width, height);
    if (!this.orbit.target) {
      // The middle of the frame's bounding box.
      const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
      for (let i = 0; i < frame.count; ++i)
        for (let a = 0; a < 3; ++a) {
          lo[a] = Math.min(lo[a], frame.means[3 * i + a]);
          hi[a] = Math.max(hi[a], frame.means[3 * i + a]);
        }
      this.orbit.placeAt(base, [0, 1, 2].map((a) => (lo[a] + hi[a]) / 2));
    }
    return { ...resized(base, width, height), ...this.orbit.pose() };
  }

  draw(frame) {
    const camera = this.viewCamera(frame);
    const canvas = $('render');
    canvas.width = camera.width;
    canvas.height = camera.height;
    const start = performance.now();
    this.renderer.render(projectSplats(this.fixed, frame, camera), this.fixed.background);
    this.renderer.finish();
    this.drawTimes.push(performance.now() - start);
    if (this.drawTimes.length > 30) this.drawTimes.shift();
    const mean = this.drawTimes.reduce((a, b) => a + b, 0) / this.drawTimes.length;
    $('render-ms').textContent = mean.toFixed(1);
    $('render-fps').textContent = mean > 0 ? (1000 / mean).toFixed(1) : 'inf';
    this.showCapturedImage();
  }

  showCapturedImage() {
    const image = $('captured');
    const split = this.frameInfo(this.frameId);
    if (this.cameraName === 'free' || !split || split.frame.split === 'meshes') {  // mesh files have no images
      image.hidden = true;
      return;
    }
    image.hidden = false;
    image.src = urlOf(this.index.urls.image, { camera: this.cameraName, frame: this.frameId });
  }

  frameInfo(id) {
    for (const take of this.takes) for (const f of take.frames) if (f.id === id) return { take, frame: f };
    return null;
  }

  showRunDetails() {
    const eval_ = $('eval');
    eval_.textContent = '';
    const models = this.index.eval ? this.index.eval.models : [];
    if (!models.length) eval_.textContent = 'no eval.json for this run';
    for (const model of models)
      for (const [split, result] of Object.entries(model.splits)) {
        const row = document.createElement('div');
        const metric = (name, digits) => {
          const m = result.metrics[name];
          return m && typeof m.mean === 'number' ? `${name} ${m.mean.toFixed(digits)}` : null;
        };
        row.textContent = [`${model.name} ${split}:`, metric('psnr', 2), metric('psnr_masked', 2), metric('ssim', 4), metric('lpips', 4)]
          .filter(Boolean).join('  ');
        eval_.appendChild(row);
      }
    $('gaussians').textContent = this.index.gaussians;
    $('fps').textContent = this.index.fps;
  }
}

function runStill(player) {
  const runs = fetchSync('/api/runs', false).runs;
  player.openRun(params.get('run') || runs[0].id);
  player.frameId = params.get('frame') || player.takes[0].frames[0].id;
  player.cameraName = params.get('camera') || player.cameras[0].name;
  if (!player.cameras.some((c) => c.name === player.cameraName)) throw new Error(`no camera ${player.cameraName}`);
  const info = player.frameInfo(player.frameId);
  if (!info) throw new Error(`no frame ${player.frameId}`);
  const frame = player.frameSync(player.frameId);
  player.draw(frame);
  $('still-png').textContent = $('render').toDataURL('image/png');
  // The frame rate: the same view drawn again, projection and sorting included.
  for (let k = 0; k < 10; ++k) player.draw(frame);
  if (params.get('take_load') === '1') {
    player.frames.clear();
    const start = performance.now();
    for (const f of info.take.frames) player.frameSync(f.id);
    $('take-load-ms').textContent = (performance.now() - start).toFixed(0);
    $('take-frames').textContent = info.take.frames.length;
  }
  $('frame-label').textContent = player.frameId;
}

// The file's Gaussians in place of the run's, drawn once from a dataset camera.
async function runSplat(player, name) {
  const runs = fetchSync('/api/runs', false).runs;
  await player.openRun(params.get('run') || runs[0].id);
  player.cameraName = params.get('camera') || player.cameras[0].name;
  if (!player.cameras.some((c) => c.name === player.cameraName)) throw new Error(`no camera ${player.cameraName}`);
  const url = `/api/splats/${encodeURIComponent(name)}`;
  const splat = await decodeSpz(await fetchAsync(url, true), player.fixed.background, url);
  player.fixed = splat.fixed;
  player.frameId = name;
  player.draw(splat.frame);
  $('still-png').textContent = $('render').toDataURL('image/png');
  $('gaussians').textContent = splat.fixed.count;
  $('frame-label').textContent = name;
}

async function runInteractive(player) {
  const runs = (await fetchAsync('/api/runs', false)).runs;
  const runSelect = $('run');
  for (const r of runs) runSelect.add(new Option(r.id, r.id));
  runSelect.value = params.get('run') || runs[0].id;
  const takeSelect = $('take'), cameraSelect = $('camera'), slider = $('frame');

  let redraw = () => {};
  const current = () => player.takes[takeSelect.selectedIndex];
  const show = async () => {
    const id = current().frames[slider.valueAsNumber].id;
    player.frameId = id;
    $('frame-label').textContent = `${id} (${current().frames[slider.valueAsNumber].split})`;
    const frame = await player.frameAsync(id);
    if (player.frameId === id) player.draw(frame);
    // Ahead of playback.
    for (let k = 1; k <= 8; ++k) {
      const next = current().frames[slider.valueAsNumber + k];
      if (next) player.frameAsync(next.id);
    }
  };
  redraw = show;

  const openRun = async () => {
    await player.openRun(runSelect.value);
    takeSelect.length = 0;
    for (const t of player.takes) takeSelect.add(new Option(`${t.name} (${t.frames.length})`, t.name));
    cameraSelect.length = 0;
    cameraSelect.add(new Option('free view', 'free'));
    for (const c of player.cameras) cameraSelect.add(new Option(`${c.name} (${c.split})`, c.name));
    const wanted = params.get('camera');
    cameraSelect.value = wanted && player.cameras.some((c) => c.name === wanted) ? wanted : player.cameras[0].name;
    player.cameraName = cameraSelect.value;
    selectTake();
  };
  const selectTake = () => {
    slider.max = current().frames.length - 1;
    slider.value = 0;
    const wanted = params.get('frame');
    const at = current().frames.findIndex((f) => f.id === wanted);
    if (at >= 0) slider.value = at;
    const start = performance.now();
    Promise.all(current().frames.map((f) => player.frameAsync(f.id))).then(() => {
      $('take-load-ms').textContent = (performance.now() - start).toFixed(0);
      $('take-frames').textContent = current().frames.length;
    });
    show();
  };
  runSelect.onchange = openRun;
  takeSelect.onchange = selectTake;
  slider.oninput = show;
  cameraSelect.onchange = () => {
    player.cameraName = cameraSelect.value;
    show();
  };

  // Playback at the capture's frame rate: a frame that is late holds the clock.
  let clockStart = 0, clockFrame = 0, shown = 0, shownSince = 0;
  const tick = async (now) => {
    if (!player.playing) return;
    const due = clockFrame + Math.floor((now - clockStart) / 1000 * player.index.fps);
    const last = current().frames.length - 1;
    const target = due > last ? 0 : due;
    if (target !== slider.valueAsNumber) {
      if (target === 0) {
        clockStart = now;
        clockFrame = 0;
      }
      const id = current().frames[target].id;
      if (player.frames.get(id) instanceof Promise || !player.frames.has(id)) {
        await player.frameAsync(id);
        clockStart = performance.now();
        clockFrame = target;
      }
      slider.value = target;
      await show();
      ++shown;
      if (now - shownSince > 1000) {
        $('play-fps').textContent = (shown * 1000 / (now - shownSince)).toFixed(1);
        shown = 0;
        shownSince = now;
      }
    }
    requestAnimationFrame(tick);
  };
  $('play').onclick = () => {
    player.playing = !player.playing;
    $('play').textContent = player.playing ? 'pause' : 'play';
    if (player.playing) {
      clockStart = performance.now();
      clockFrame = slider.valueAsNumber;
      shownSince = clockStart;
      shown = 0;
      requestAnimationFrame(tick);
    }
  };

  // Orbit, pan, zoom: any drag leaves the dataset camera for the free view from where it was.
  const canvas = $('render');
  let dragging = null;
  const toFree = () => {
    if (player.cameraName === 'free') return;
    const base = player.cameras.find((c) => c.name === player.cameraName);
    const target = player.orbit.target || [0, 1, 2].map(() => 0);
    player.orbit.placeAt(base, player.orbit.target ? target : centreOfFrame(player));
    player.cameraName = 'free';
    cameraSelect.value = 'free';
  };
  canvas.addEventListener('contextmenu', (e) => e.preventDefault());
  canvas.addEventListener('pointerdown', (e) => {
    toFree();
    dragging = { x: e.clientX, y: e.clientY, pan: e.shiftKey || e.button === 2 };
    canvas.setPointerCapture(e.pointerId);
  });
  canvas.addEventListener('pointermove', (e) => {
    if (!dragging) return;
    const dx = e.clientX - dragging.x, dy = e.clientY - dragging.y;
    dragging.x = e.clientX;
    dragging.y = e.clientY;
    if (dragging.pan) player.orbit.pan(dx, dy, player.viewCamera(player.frames.get(player.frameId)).fx);
    else player.orbit.rotate(dx, dy);
    redraw();
  });
  canvas.addEventListener('pointerup', () => (dragging = null));
  canvas.addEventListener('wheel', (e) => {
    e.preventDefault();
    toFree();
    player.orbit.zoom(Math.exp(e.deltaY * 0.001));
    redraw();
  }, { passive: false });

  await openRun();
}

function centreOfFrame(player) {
  const frame = player.frames.get(player.frameId);
  if (!frame || frame instanceof Promise) return cameraCentre(player.cameras[0]);
  const sum = [0, 0, 0];
  for (let i = 0; i < frame.count; ++i) for (let a = 0; a < 3; ++a) sum[a] += frame.means[3 * i + a] / frame.count;
  return sum;
}

function fail(error) {
  document.body.dataset.state = 'error';
  $('error').textContent = String(error && error.stack ? error.stack : error);
}

try {
  document.body.classList.toggle('still', still);
  const player = new Player();
  if (params.get('splat')) {
    runSplat(player, params.get('splat')).then(() => (document.body.dataset.state = still ? 'done' : 'ready'), fail);
  } else if (still) {
    runStill(player);
    document.body.dataset.state = 'done';
  } else {
    runInteractive(player).then(() => (document.body.dataset.state = 'ready'), fail);
  }
} catch (error) {
  fail(error);
}
