// Blends projected splats (projection.js) on the GPU with WebGL2: one
// instanced quad per splat over its footprint, alpha = min(0.99,
// opacity·exp(-½ dᵀ conic d)) at each pixel centre, skipped below 1/255, drawn
// back to front with "over" blending onto the run's background, which equals
// tega's front-to-back compositing. Blending happens in a float target: in
// the canvas's 8 bits every blend would round.

import { FLOATS_PER_SPLAT } from './projection.js';

const SPLAT_VERTEX = `#version 300 es
precision highp float;
in vec2 corner;
in vec4 centreExtent;   // u, v, extent x, y (pixels; pixel (0,0) is the top-left pixel's centre)
in vec4 conicOpacity;
in vec4 colour;
uniform vec2 viewport;
flat out vec4 vConicOpacity;
flat out vec2 vCentre;
flat out vec3 vColour;
void main() {
  vec2 pixel = centreExtent.xy + corner * centreExtent.zw;
  gl_Position = vec4((pixel.x + 0.5) / viewport.x * 2.0 - 1.0, 1.0 - (pixel.y + 0.5) / viewport.y * 2.0, 0.0, 1.0);
  vConicOpacity = conicOpacity;
  vCentre = centreExtent.xy;
  vColour = colour.rgb;
}`;

const SPLAT_FRAGMENT = `#version 300 es
precision highp float;
flat in vec4 vConicOpacity;
flat in vec2 vCentre;
flat in vec3 vColour;
uniform vec2 viewport;
out vec4 result;
void main() {
  vec2 d = vec2(gl_FragCoord.x - 0.5, viewport.y - gl_FragCoord.y - 0.5) - vCentre;
  float power = -0.5 * (vConicOpacity.x * d.x * d.x + vConicOpacity.z * d.y * d.y) - vConicOpacity.y * d.x * d.y;
  float alpha = min(0.99, vConicOpacity.w * exp(power));
  if (alpha < 1.0 / 255.0) discard;
  result = vec4(vColour * alpha, alpha);
}`;

const COPY_VERTEX = `#version 300 es
in vec2 corner;
void main() { gl_Position = vec4(corner, 0.0, 1.0); }`;

const COPY_FRAGMENT = `#version 300 es
precision highp float;
uniform sampler2D image;
out vec4 result;
void main() { result = vec4(clamp(texelFetch(image, ivec2(gl_FragCoord.xy), 0).rgb, 0.0, 1.0), 1.0); }`;

function compile(gl, vertex, fragment) {
  const program = gl.createProgram();
  for (const [type, source] of [[gl.VERTEX_SHADER, vertex], [gl.FRAGMENT_SHADER, fragment]]) {
    const shader = gl.createShader(type);
    gl.shaderSource(shader, source);
    gl.compileShader(shader);
    if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(shader));
    gl.attachShader(program, shader);
  }
  gl.linkProgram(program);
  if (!gl.getProgramParameter(program, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(program));
  return program;
}

export class SplatRenderer {
  constructor(canvas) {
    const gl = canvas.getContext('webgl2', { alpha: false, antialias: false, depth: false, preserveDrawingBuffer: true });
    if (!gl) throw new Error('this browser has no WebGL2');
    if (!gl.getExtension('EXT_color_buffer_float')) throw new Error('this browser cannot render to float textures');
    // 32-bit blending where the browser offers it, else half floats.
    this.floatFormat = gl.getExtension('EXT_float_blend') ? gl.RGBA32F : gl.RGBA16F;
    this.gl = gl;
    this.canvas = canvas;
    this.splatProgram = compile(gl, SPLAT_VERTEX, SPLAT_FRAGMENT);
    this.copyProgram = compile(gl, COPY_VERTEX, COPY_FRAGMENT);
    this.quad = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, this.quad);
    gl.bufferData(gl.ARRAY_BUFFER, new Float32Array([-1, -1, 1, -1, -1, 1, 1, 1]), gl.STATIC_DRAW);
    this.instances = gl.createBuffer();
    this.splatVao = this.makeSplatVao();
    this.copyVao = gl.createVertexArray();
    gl.bindVertexArray(this.copyVao);
    const corner = gl.getAttribLocation(this.copyProgram, 'corner');
    gl.bindBuffer(gl.ARRAY_BUFFER, this.quad);
    gl.enableVertexAttribArray(corner);
    gl.vertexAttribPointer(corner, 2, gl.FLOAT, false, 0, 0);
    gl.bindVertexArray(null);
    this.target = null;
  }

  makeSplatVao() {
    const gl = this.gl, program = this.splatProgram;
    const vao = gl.createVertexArray();
    gl.bindVertexArray(vao);
    gl.bindBuffer(gl.ARRAY_BUFFER, this.quad);
    const corner = gl.getAttribLocation(program, 'corner');
    gl.enableVertexAttribArray(corner);
    gl.vertexAttribPointer(corner, 2, gl.FLOAT, false, 0, 0);
    gl.bindBuffer(gl.ARRAY_BUFFER, this.instances);
    ['centreExtent', 'conicOpacity', 'colour'].forEach((name, k) => {
      const location = gl.getAttribLocation(program, name);
      gl.enableVertexAttribArray(location);
      gl.vertexAttribPointer(location, 4, gl.FLOAT, false, 4 * FLOATS_PER_SPLAT, 16 * k);
      gl.vertexAttribDivisor(location, 1);
    });
    gl.bindVertexArray(null);
    return vao;
  }

  // A float colour target of the canvas's size.
  ensureTarget(width, height) {
    const gl = this.gl;
    if (this.target && this.target.width === width && this.target.height === height) return this.target;
    if (this.target) {
      gl.deleteTexture(this.target.texture);
      gl.deleteFramebuffer(this.target.framebuffer);
    }
    const texture = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, texture);
    gl.texStorage2D(gl.TEXTURE_2D, 1, this.floatFormat, width, height);
    // Float32 textures are not filterable: a filtering sampler would read zeros.
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
    const framebuffer = gl.createFramebuffer();
    gl.bindFramebuffer(gl.FRAMEBUFFER, framebuffer);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, texture, 0);
    if (gl.checkFramebufferStatus(gl.FRAMEBUFFER) !== gl.FRAMEBUFFER_COMPLETE) throw new Error('float render target unsupported');
    this.target = { width, height, texture, framebuffer };
    return this.target;
  }

  // splats: projectSplats()'s output for a camera of the canvas's size.
  render(splats, background) {
    const gl = this.gl, { width, height } = this.canvas;
    const target = this.ensureTarget(width, height);
    gl.bindFramebuffer(gl.FRAMEBUFFER, target.framebuffer);
    gl.viewport(0, 0, width, height);
    gl.clearColor(background[0], background[1], background[2], 1);
    gl.clear(gl.COLOR_BUFFER_BIT);
    gl.useProgram(this.splatProgram);
    gl.uniform2f(gl.getUniformLocation(this.splatProgram, 'viewport'), width, height);
    gl.bindBuffer(gl.ARRAY_BUFFER, this.instances);
    gl.bufferData(gl.ARRAY_BUFFER, splats.data, gl.DYNAMIC_DRAW);
    gl.enable(gl.BLEND);
    gl.blendFunc(gl.ONE, gl.ONE_MINUS_SRC_ALPHA);
    gl.bindVertexArray(this.splatVao);
    gl.drawArraysInstanced(gl.TRIANGLE_STRIP, 0, 4, splats.count);
    gl.disable(gl.BLEND);

    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    gl.useProgram(this.copyProgram);
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D, target.texture);
    gl.uniform1i(gl.getUniformLocation(this.copyProgram, 'image'), 0);
    gl.bindVertexArray(this.copyVao);
    gl.drawArrays(gl.TRIANGLE_STRIP, 0, 4);
    gl.bindVertexArray(null);
  }

  finish() {
    this.gl.finish();
  }
}
