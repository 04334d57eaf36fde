// The Vertex BRDF web viewer: loads the GLB written by the exporter (embedded in the page, or by
// URL in the hosted variant) with three.js's GLTFLoader and draws it with the product's model:
// the fragment shader is the text of shaders/reflectance_model.glsl (put into the page verbatim at build
// time, element #vbrdf-model-glsl) followed by this viewer's main(), as the relight renderer and
// the live view each put their own main() after it. Nothing is fetched at run time but the GLB URL
// of the hosted variant.
//
// Differences from the relight renderer (as the live view's, docs/live_relighting.md): no cast
// shadows (N.L <= 0 is black); output multiplied by the exposure, clipped at 1 and sRGB-encoded;
// vertices without a model grey. renderLinear() (for tests) writes the renderer's own output:
// linear values, RelitPixel class in alpha.
import * as THREE from 'three';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';

const t0 = performance.now();
const MODEL_GLSL = document.getElementById('vbrdf-model-glsl').textContent;
// shaders/subpixel_grid.glsl (snap_to_subpixel_grid), as the relight renderer's vertex shader starts.
const GRID_GLSL = document.getElementById('vbrdf-grid-glsl').textContent;

const VERTEX_SHADER = GRID_GLSL + `
in vec3 a_rho;
in float a_ks;
in float a_shininess;
in float a_diffuse_form;
in float a_fit_status;
in float a_dq;
in float a_sq;
uniform float u_typical_shininess;
uniform vec2 u_viewport;
out vec3 v_position;
out vec3 v_normal;
out vec4 v_rho_fitted;
out vec2 v_ks_alpha;
out float v_coated;
out vec3 v_status_dq_sq;
out float v_ks;
out float v_shininess;
void main() {
  vec4 world = modelMatrix * vec4(position, 1.0);
  v_position = world.xyz;
  v_normal = normal;
  // As upload_model_mesh: fitted = fit_status != 0; k_s = 0 vertices take the median shininess.
  v_rho_fitted = vec4(a_rho, a_fit_status > 0.5 ? 1.0 : 0.0);
  v_ks_alpha = vec2(a_ks, a_ks > 0.0 && a_shininess > 0.0 ? a_shininess : u_typical_shininess);
  v_coated = a_diffuse_form > 0.5 ? 1.0 : 0.0;
  v_status_dq_sq = vec3(a_fit_status, a_dq, a_sq);
  v_ks = a_ks;
  v_shininess = a_shininess;
  gl_Position = snap_to_subpixel_grid(projectionMatrix * viewMatrix * world, u_viewport);
}
`;

// The viewer's main(): what follows the model's text in the fragment shader.
const FRAGMENT_MAIN = `
in vec3 v_position;
in vec3 v_normal;
in vec4 v_rho_fitted;
in vec2 v_ks_alpha;
in float v_coated;
in vec3 v_status_dq_sq;
in float v_ks;
in float v_shininess;
uniform vec3 u_light_dir;
uniform int u_mode;            // 0 relit, 1 albedo, 2 specular, 3 k_s, 4 shininess, 5 fit_status, 6 DQ, 7 SQ
uniform int u_linear_output;   // 1: the relight renderer's output (linear, class in alpha)
uniform float u_exposure;
uniform vec3 u_status_colors[5];
uniform vec3 u_quality_colors[3];
uniform vec3 u_ramp[3];
uniform vec2 u_ks_range;
uniform vec2 u_log_shininess_range;
layout(location = 0) out vec4 o_color;

vec3 ramp(float t) {
  t = clamp(t, 0.0, 1.0);
  return t < 0.5 ? mix(u_ramp[0], u_ramp[1], 2.0 * t) : mix(u_ramp[1], u_ramp[2], 2.0 * t - 1.0);
}
vec3 quality_color(float q) {
  float t = clamp(q, 0.0, 2.0);
  return t >= 1.0 ? mix(u_quality_colors[1], u_quality_colors[2], t - 1.0) : mix(u_quality_colors[0], u_quality_colors[1], t);
}

void main() {
  vec3 n = unit_normal(v_normal);
  float footprint = pixel_footprint_variance(n);
  vec3 l = u_light_dir;
  float d = dot(n, l);
  vec3 e = normalize(cameraPosition - v_position);
  bool fitted = !(v_rho_fitted.a < 0.999);
  if (u_linear_output != 0) {
    if (!fitted) { o_color = vec4(0.0, 0.0, 0.0, 3.0); return; }
    if (!(d > 0.0)) { o_color = vec4(0.0, 0.0, 0.0, 2.0); return; }
    vec3 diffuse;
    float spec;
    reflectance_terms(v_rho_fitted.rgb, v_ks_alpha.x, v_ks_alpha.y, v_coated, n, l, e, footprint, diffuse, spec);
    o_color = vec4(diffuse + vec3(spec), 1.0);
    return;
  }
  float shade = 0.35 + 0.65 * max(d, 0.0);
  if (u_mode >= 3) {
    vec3 c;
    if (u_mode == 5) {
      int s = int(clamp(floor(v_status_dq_sq.x + 0.5), 0.0, 4.0));
      c = u_status_colors[s];
    } else if (!fitted) {
      c = u_status_colors[0];
    } else if (u_mode == 3) {
      c = ramp((v_ks - u_ks_range.x) / max(u_ks_range.y - u_ks_range.x, 1e-12));
    } else if (u_mode == 4) {
      c = v_ks > 0.0 && v_shininess > 0.0
        ? ramp((log(v_shininess) - u_log_shininess_range.x) / max(u_log_shininess_range.y - u_log_shininess_range.x, 1e-6))
        : u_status_colors[1];
    } else {
      c = quality_color(u_mode == 6 ? v_status_dq_sq.y : v_status_dq_sq.z);
    }
    o_color = vec4(c * shade, 1.0);
    return;
  }
  if (!fitted) { o_color = vec4(vec3(0.35) * shade, 1.0); return; }
  if (u_mode == 1) { o_color = vec4(srgb(v_rho_fitted.rgb * u_exposure), 1.0); return; }
  if (!(d > 0.0)) { o_color = vec4(0.0, 0.0, 0.0, 1.0); return; }
  vec3 diffuse;
  float spec;
  reflectance_terms(v_rho_fitted.rgb, v_ks_alpha.x, v_ks_alpha.y, v_coated, n, l, e, footprint, diffuse, spec);
  vec3 c = u_mode == 2 ? vec3(spec) : diffuse + vec3(spec);
  o_color = vec4(srgb(c * u_exposure), 1.0);
}
`;

// The model's uniforms as set_reflectance_model_uniforms sets them (lobe form from the GLB's extras).
function modelUniforms(model) {
  const lobe = model.lobe_form | 0;
  return {
    u_half_angle_lobe: { value: lobe !== 0 ? 1 : 0 },
    u_ggx_lobe: { value: lobe === 2 ? 1 : 0 },
    u_coat_index: { value: model.coat_index },
    u_coat_min_cosine: { value: model.coat_min_cosine },
  };
}

const RAMP = [[0.07, 0.10, 0.45], [0.10, 0.62, 0.60], [0.98, 0.90, 0.20]];
const MODES = ['relit', 'albedo', 'specular only', 'k_s', 'shininess', 'fit_status', 'DQ', 'SQ'];

function decodeBase64(text) {
  const bin = atob(text.replace(/\s+/g, ''));
  const out = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; ++i) out[i] = bin.charCodeAt(i);
  return out.buffer;
}

async function glbBytes() {
  const embedded = document.getElementById('vbrdf-glb').textContent.trim();
  if (embedded) return decodeBase64(embedded);
  const url = document.getElementById('vbrdf-glb-url').textContent.trim();
  if (!url) throw new Error('this page carries no GLB and no GLB URL: write it again with the exporter');
  const response = await fetch(url);
  if (!response.ok) throw new Error(`cannot load ${url}: ${response.status} ${response.statusText}`);
  return response.arrayBuffer();
}

function parseGltf(buffer) {
  return new Promise((resolve, reject) => new GLTFLoader().parse(buffer, '', resolve, reject));
}

function colorsToUniform(list) {
  return list.map((e) => new THREE.Vector3(e.rgb[0], e.rgb[1], e.rgb[2]));
}

function quantiles(values, mask, lo, hi) {
  const v = [];
  for (let i = 0; i < values.length; ++i) if (mask(i)) v.push(values[i]);
  if (!v.length) return [0, 1];
  v.sort((a, b) => a - b);
  return [v[Math.floor(lo * (v.length - 1))], v[Math.floor(hi * (v.length - 1))]];
}

class Viewer {
  constructor() {
    this.canvas = document.getElementById('view');
    this.renderer = new THREE.WebGLRenderer({ canvas: this.canvas, antialias: false, preserveDrawingBuffer: true });
    this.renderer.outputColorSpace = THREE.LinearSRGBColorSpace;
    this.renderer.setPixelRatio(window.devicePixelRatio || 1);
    this.renderer.setClearColor(0x202225, 1);
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(35, 1, 0.01, 100);
    this.controls = new OrbitControls(this.camera, this.canvas);
    this.controls.enableDamping = false;
    this.lightDir = new THREE.Vector3(0, 0, 1);
    this.exposure = 1;
    this.mode = 0;
    this.showLights = true;
    this.photoLights = [];
  }

  async load() {
    const buffer = await glbBytes();
    const gltf = await parseGltf(buffer);
    this.json = gltf.parser.json;
    const prim = this.json.meshes[0].primitives[0];
    this.model = (prim.extras || {}).vbrdf_model;
    if (!this.model) throw new Error('the GLB declares no Vertex BRDF model (primitive extras.vbrdf_model)');
    this.capture = ((this.json.scenes[0] || {}).extras || {}).vbrdf_capture || { photo_lights: [], cameras: [] };
    let mesh = null;
    gltf.scene.traverse((o) => { if (o.isMesh && !mesh) mesh = o; });
    const g = mesh.geometry;
    const need = ['position', 'normal', 'color', '_ks', '_shininess', '_diffuse_form', '_fit_status', '_dq', '_sq'];
    for (const name of need)
      if (!g.getAttribute(name)) throw new Error(`the GLB lacks the attribute ${name.toUpperCase()}`);
    g.setAttribute('a_rho', g.getAttribute('_albedo') || g.getAttribute('color'));
    for (const name of ['ks', 'shininess', 'diffuse_form', 'fit_status', 'dq', 'sq']) g.setAttribute('a_' + name, g.getAttribute('_' + name));
    this.geometry = g;
    const ks = g.getAttribute('_ks').array, sh = g.getAttribute('_shininess').array, st = g.getAttribute('_fit_status').array;
    const fitted = (i) => st[i] > 0.5;
    this.ksRange = [0, quantiles(ks, fitted, 0, 0.99)[1] || 1];
    const logSh = Float32Array.from(sh, (v) => (v > 0 ? Math.log(v) : 0));
    this.logShininessRange = quantiles(logSh, (i) => fitted(i) && ks[i] > 0 && sh[i] > 0, 0.01, 0.99);
    const legends = this.model.legends || {};
    this.statusColors = legends.fit_status || [
      { label: '0 no fit', rgb: [0.35, 0.35, 0.35] }, { label: '1 diffuse only', rgb: [0.2, 0.45, 0.9] },
      { label: '2 full fit', rgb: [0.2, 0.75, 0.25] }, { label: '3 from neighbours', rgb: [0.95, 0.6, 0.1] },
      { label: '4 from weak samples', rgb: [0.7, 0.3, 0.8] }];
    this.qualityColors = legends.quality || [
      { label: '0 poor', rgb: [0.85, 0.15, 0.1] }, { label: '1 fair', rgb: [0.95, 0.85, 0.2] },
      { label: '2 good', rgb: [0.15, 0.7, 0.25] }];
    this.material = new THREE.ShaderMaterial({
      glslVersion: THREE.GLSL3,
      vertexShader: VERTEX_SHADER,
      fragmentShader: MODEL_GLSL + '\n' + FRAGMENT_MAIN,
      side: THREE.DoubleSide,
      uniforms: {
        ...modelUniforms(this.model),
        u_typical_shininess: { value: this.model.typical_shininess },
        u_light_dir: { value: this.lightDir },
        u_viewport: { value: new THREE.Vector2(1, 1) },
        u_mode: { value: 0 },
        u_linear_output: { value: 0 },
        u_exposure: { value: 1 },
        u_status_colors: { value: colorsToUniform(this.statusColors) },
        u_quality_colors: { value: colorsToUniform(this.qualityColors) },
        u_ramp: { value: RAMP.map((c) => new THREE.Vector3(...c)) },
        u_ks_range: { value: new THREE.Vector2(...this.ksRange) },
        u_log_shininess_range: { value: new THREE.Vector2(...this.logShininessRange) },
      },
    });
    this.mesh = new THREE.Mesh(g, this.material);
    this.mesh.frustumCulled = false;
    this.scene.add(this.mesh);
    g.computeBoundingSphere();
    this.sphere = g.boundingSphere;
    this.photoLights = (this.capture.photo_lights || []).map((l) => new THREE.Vector3(...l.direction).normalize());
    this.addLightDots();
    this.frameView();
    this.loadMs = performance.now() - t0;
  }

  addLightDots() {
    const r = this.sphere.radius * 1.6;
    const pos = new Float32Array(this.photoLights.length * 3);
    this.photoLights.forEach((d, i) => pos.set([this.sphere.center.x + d.x * r, this.sphere.center.y + d.y * r, this.sphere.center.z + d.z * r], 3 * i));
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(pos, 3));
    this.dots = new THREE.Points(g, new THREE.PointsMaterial({ color: 0xffd23c, size: 6, sizeAttenuation: false }));
    this.scene.add(this.dots);
  }

  frameView() {
    const c = this.sphere.center, r = this.sphere.radius;
    const cam = (this.capture.cameras || [])[0];
    this.controls.target.copy(c);
    if (cam) {
      // The first viewpoint of the capture: its centre, looking at the object, its field of view.
      this.camera.position.set(...cam.position);
      this.camera.fov = THREE.MathUtils.radToDeg(2 * Math.atan(cam.height / 2 / cam.focal_px));
      const m = new THREE.Matrix4().fromArray(cam.view_matrix).invert();
      this.camera.up.set(m.elements[4], m.elements[5], m.elements[6]);
    } else {
      this.camera.position.set(c.x, c.y, c.z + 2.8 * r);
    }
    this.camera.near = r * 0.01;
    this.camera.far = this.camera.position.distanceTo(c) + r * 4;
    this.camera.updateProjectionMatrix();
    this.controls.update();
    // The light starts at the view direction, tilted up and to the left.
    const toCamera = this.camera.position.clone().sub(c).normalize();
    const up = this.camera.up.clone().normalize();
    const right = new THREE.Vector3().crossVectors(up, toCamera).normalize();
    this.lightDir.copy(toCamera).addScaledVector(up, 0.5).addScaledVector(right, -0.4).normalize();
  }

  resize() {
    const w = this.canvas.clientWidth, h = this.canvas.clientHeight;
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / Math.max(h, 1);
    this.camera.updateProjectionMatrix();
  }

  draw() {
    if (!this.mesh) return;
    const u = this.material.uniforms;
    u.u_mode.value = this.mode;
    u.u_exposure.value = this.exposure;
    u.u_linear_output.value = 0;
    this.dots.visible = this.showLights;
    this.renderer.setRenderTarget(null);
    this.renderer.getDrawingBufferSize(u.u_viewport.value);
    this.renderer.render(this.scene, this.camera);
    drawLightSphere(this);
  }

  // Test hook: renders the model as the relight renderer does (linear RGB, class in alpha) for a
  // column-major world->camera `view` and `projection` into a width x height float target and
  // returns its pixels, row 0 = top (the relight renderer's order).
  renderLinear(view, projection, width, height, light) {
    // Float colour and a 32-bit float depth buffer, as the relight renderer's target.
    const depthTexture = new THREE.DepthTexture(width, height, THREE.FloatType);
    const target = new THREE.WebGLRenderTarget(width, height, {
      type: THREE.FloatType, format: THREE.RGBAFormat, depthBuffer: true, depthTexture,
      minFilter: THREE.NearestFilter, magFilter: THREE.NearestFilter,
    });
    const cam = new THREE.Camera();
    cam.matrixAutoUpdate = false;
    cam.matrix.fromArray(view).invert();
    cam.matrixWorld.copy(cam.matrix);
    cam.matrixWorldInverse.fromArray(view);
    cam.projectionMatrix.fromArray(projection);
    cam.projectionMatrixInverse.copy(cam.projectionMatrix).invert();
    cam.matrixWorldAutoUpdate = false;
    const u = this.material.uniforms;
    const saved = this.lightDir.clone();
    this.lightDir.set(light[0], light[1], light[2]).normalize();
    u.u_linear_output.value = 1;
    u.u_viewport.value.set(width, height);
    const dots = this.dots.visible;
    this.dots.visible = false;
    this.renderer.setRenderTarget(target);
    this.renderer.setClearColor(0x000000, 0);
    this.renderer.clear();
    this.renderer.render(this.scene, cam);
    const pixels = new Float32Array(width * height * 4);
    this.renderer.readRenderTargetPixels(target, 0, 0, width, height, pixels);
    this.renderer.setRenderTarget(null);
    this.renderer.setClearColor(0x202225, 1);
    target.dispose();
    u.u_linear_output.value = 0;
    this.dots.visible = dots;
    this.lightDir.copy(saved);
    const flipped = new Float32Array(pixels.length);
    const row = width * 4;
    for (let y = 0; y < height; ++y) flipped.set(pixels.subarray((height - 1 - y) * row, (height - y) * row), y * row);
    return flipped;
  }

  // Test hook: median time of `frames` full draws of the current view, each waited for (a one-pixel
  // read back ends the frame's GPU work).
  measureFrames(frames) {
    const gl = this.renderer.getContext();
    const px = new Uint8Array(4);
    const times = [];
    for (let i = 0; i < frames; ++i) {
      const s = performance.now();
      this.draw();
      gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
      times.push(performance.now() - s);
    }
    times.sort((a, b) => a - b);
    return times[Math.floor(times.length / 2)];
  }

  rendererName() {
    const gl = this.renderer.getContext();
    const ext = gl.getExtension('WEBGL_debug_renderer_info');
    return ext ? gl.getParameter(ext.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER);
  }
}

// The light sphere (bottom right): the hemisphere facing the viewer; the current light (orange)
// and the photo lights (yellow; dimmer behind), in the camera's frame.
function drawLightSphere(v) {
  const c = document.getElementById('lightsphere');
  const ctx = c.getContext('2d');
  const R = c.width / 2 - 6, cx = c.width / 2, cy = c.height / 2;
  ctx.clearRect(0, 0, c.width, c.height);
  ctx.fillStyle = 'rgba(20, 22, 25, 0.82)';
  ctx.beginPath(); ctx.arc(cx, cy, R, 0, 2 * Math.PI); ctx.fill();
  ctx.strokeStyle = '#888'; ctx.lineWidth = 2; ctx.stroke();
  const toCam = new THREE.Matrix4().extractRotation(v.camera.matrixWorldInverse);
  const plot = (d, color, size) => {
    const p = d.clone().applyMatrix4(toCam);
    ctx.globalAlpha = p.z >= 0 ? 1 : 0.3;
    ctx.fillStyle = color;
    ctx.beginPath(); ctx.arc(cx + p.x * R, cy - p.y * R, size, 0, 2 * Math.PI); ctx.fill();
    ctx.globalAlpha = 1;
    return p;
  };
  if (v.showLights) for (const d of v.photoLights) plot(d, '#ffd23c', 4);
  const p = plot(v.lightDir, '#ff7a1a', 9);
  ctx.strokeStyle = '#ff7a1a';
  ctx.beginPath(); ctx.moveTo(cx, cy); ctx.lineTo(cx + p.x * R, cy - p.y * R); ctx.stroke();
}

// A light direction from a point on a disc (x, y in [-1, 1], y up) in the camera's frame.
function lightFromDisc(v, x, y) {
  const r2 = x * x + y * y;
  const p = r2 <= 1 ? new THREE.Vector3(x, y, Math.sqrt(1 - r2)) : new THREE.Vector3(x, y, 0).normalize();
  v.lightDir.copy(p.applyMatrix4(new THREE.Matrix4().extractRotation(v.camera.matrixWorld))).normalize();
}

// "1 viewpoint", "3 viewpoints".
const counted = (n, noun) => `${n} ${noun}${n === 1 ? '' : 's'}`;

function legendHtml(v) {
  const swatch = (e) => `<div class="row"><span class="swatch" style="background:${css(e.rgb)}"></span>${e.label}</div>`;
  const ramp = (lo, hi, label) =>
    `<div>${label}</div><div class="ramp" style="background:linear-gradient(to right,${RAMP.map(css).join(',')})"></div>` +
    `<div class="ends"><span>${lo}</span><span>${hi}</span></div>`;
  switch (v.mode) {
    case 0: return 'k_d C d + k_s g(s, alpha), lit by the light on the sphere; exposure before clipping at 1 and sRGB';
    case 1: return 'linear k_d C (unlit), times the exposure, sRGB';
    case 2: return 'k_s g(s, alpha) alone (grey)';
    case 3: return ramp('0', v.ksRange[1].toPrecision(3), 'k_s (99th percentile at the top)') + swatch({ label: 'no model', rgb: v.statusColors[0].rgb });
    case 4: return ramp(Math.exp(v.logShininessRange[0]).toPrecision(3), Math.exp(v.logShininessRange[1]).toPrecision(3), 'shininess alpha, log scale') +
      swatch({ label: 'k_s = 0 (no lobe)', rgb: v.statusColors[1].rgb }) + swatch({ label: 'no model', rgb: v.statusColors[0].rgb });
    case 5: return v.statusColors.map(swatch).join('');
    default: return v.qualityColors.map(swatch).join('') + '<div>linear between; higher is better</div>';
  }
}
function css(rgb) { return `rgb(${rgb.map((x) => Math.round(255 * x)).join(',')})`; }

async function main() {
  const v = new Viewer();
  window.vbrdfViewer = v;
  const message = document.getElementById('message');
  try {
    await v.load();
  } catch (err) {
    message.textContent = 'Cannot show the model: ' + err.message;
    window.vbrdfError = err.message;
    throw err;
  }
  message.style.display = 'none';
  const modeSel = document.getElementById('mode');
  const exposure = document.getElementById('exposure');
  const legend = document.getElementById('legend');
  const update = () => {
    v.mode = Number(modeSel.value);
    v.exposure = Math.pow(2, Number(exposure.value));
    document.getElementById('exposure-value').textContent = 'x' + (+v.exposure.toPrecision(3));
    v.showLights = document.getElementById('show-lights').checked;
    legend.innerHTML = legendHtml(v);
    v.draw();
  };
  modeSel.addEventListener('change', update);
  exposure.addEventListener('input', update);
  document.getElementById('show-lights').addEventListener('change', update);
  v.controls.addEventListener('change', () => v.draw());
  window.addEventListener('resize', () => { v.resize(); v.draw(); });
  const n = v.geometry.getAttribute('position').count;
  let modelled = 0;
  const st = v.geometry.getAttribute('_fit_status').array;
  for (let i = 0; i < n; ++i) modelled += st[i] > 0.5 ? 1 : 0;
  document.getElementById('info').textContent =
    `${n.toLocaleString('en')} vertices, ${modelled.toLocaleString('en')} with a model\n` +
    `lobe ${v.model.lobe_form_name}, diffuse ${v.model.diffuse_form}\n` +
    `${counted(v.photoLights.length, 'photo light')}, ${counted((v.capture.cameras || []).length, 'viewpoint')}\n` +
    `loaded in ${Math.round(v.loadMs)} ms`;

  // The light: drag on the sphere, or Shift (or Ctrl) + drag in the view.
  const sphere = document.getElementById('lightsphere');
  let dragging = false;
  const fromSphere = (ev) => {
    const r = sphere.getBoundingClientRect();
    lightFromDisc(v, ((ev.clientX - r.left) / r.width) * 2 - 1, 1 - ((ev.clientY - r.top) / r.height) * 2);
    v.draw();
  };
  sphere.addEventListener('pointerdown', (ev) => { dragging = true; sphere.setPointerCapture(ev.pointerId); fromSphere(ev); });
  sphere.addEventListener('pointermove', (ev) => { if (dragging) fromSphere(ev); });
  sphere.addEventListener('pointerup', () => { dragging = false; });
  let viewDrag = false;
  v.canvas.addEventListener('pointerdown', (ev) => {
    if (!(ev.shiftKey || ev.ctrlKey)) return;
    viewDrag = true;
    v.controls.enabled = false;
    v.canvas.setPointerCapture(ev.pointerId);
  }, true);
  v.canvas.addEventListener('pointermove', (ev) => {
    if (!viewDrag) return;
    const r = v.canvas.getBoundingClientRect();
    const s = Math.min(r.width, r.height) / 2;
    lightFromDisc(v, (ev.clientX - r.left - r.width / 2) / s, (r.height / 2 - (ev.clientY - r.top)) / s);
    v.draw();
  });
  v.canvas.addEventListener('pointerup', () => { viewDrag = false; v.controls.enabled = true; });
  v.resize();
  update();
  document.body.dataset.ready = '1';
}

window.vbrdfReady = main();
