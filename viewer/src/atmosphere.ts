// The atmosphere on the GPU: the uniforms, the GLSL of the single-scattering model of
// atmosphereModel.ts (the same formulas and sample counts), the sky drawn behind the terrain and
// the aerial perspective the terrain's shader applies to its colour.
//
// The sky is a full-screen triangle drawn after the opaque terrain at the far plane, depth-tested:
// it costs only the pixels where nothing else is drawn. Its ray starts at the camera: in the
// planet frame the camera sits at `up * (R + h)` with `h` its height above the ground sphere,
// computed in f64 (`h (2R + h)` stands for r^2 - R^2 in the ray's quadratics), so the horizon
// stays sharp on the ground of an Earth-sized planet.

import * as THREE from 'three';
import {
  AERIAL_SAMPLES,
  DEFAULT_SUN,
  SKY_SAMPLES,
  SPACE,
  SUN_DISC,
  SUN_RADIUS,
  SURFACE_SCATTER,
  sunDirection,
  type AtmosphereParams,
} from './atmosphereModel';
import { enuAt, length, type V3 } from './frames';

/** The uniforms of the atmosphere, shared by the sky and every terrain material. */
export function createAtmosphereUniforms() {
  return {
    uAtmoOn: { value: 0 },
    uAtmoUp: { value: new THREE.Vector3(0, 1, 0) },
    uAtmoCamH: { value: 1 },
    uAtmoR: { value: 1 },
    uAtmoTop: { value: 1 },
    uAtmoRayleigh: { value: new THREE.Vector3() },
    uAtmoRayleighExt: { value: new THREE.Vector3() },
    uAtmoRayleighH: { value: 1 },
    uAtmoMie: { value: new THREE.Vector3() },
    uAtmoMieExt: { value: new THREE.Vector3() },
    uAtmoMieH: { value: 1 },
    uAtmoMieG: { value: 0.76 },
    uAtmoSunPathX: { value: 0 },
    uAtmoSunLight: { value: new THREE.Vector3(1, 1, 1) },
    uAtmoSun: { value: new THREE.Vector3(0, 1, 0) },
  };
}

export type AtmosphereUniforms = ReturnType<typeof createAtmosphereUniforms>;

const f = (x: number): string => (Number.isInteger(x) ? `${x}.0` : String(x));

/**
 * GLSL of the model: uniforms, phase functions, the Chapman approximation, the span of a ray in
 * the shell, the march, and `vec3 pmcAerialPerspective(vec3 colour, vec3 rel)` (the colour of a
 * surface at `rel` from the camera, render space, seen through the air). With the atmosphere
 * off (`uAtmoOn` 0: a planet without air, the back-face test mode, lighting off) it returns the
 * colour unchanged.
 */
export const ATMOSPHERE_GLSL = /* glsl */ `
uniform float uAtmoOn;
uniform vec3 uAtmoUp;          // unit, from the planet's centre to the camera
uniform float uAtmoCamH;       // the camera's height above the ground sphere (>= 1 mm)
uniform float uAtmoR;          // radius of the ground sphere
uniform float uAtmoTop;        // thickness of the shell
uniform vec3 uAtmoRayleigh;    // scattering at the ground, per metre
uniform vec3 uAtmoRayleighExt;
uniform float uAtmoRayleighH;
uniform vec3 uAtmoMie;
uniform vec3 uAtmoMieExt;
uniform float uAtmoMieH;
uniform float uAtmoMieG;
uniform float uAtmoSunPathX;   // the sun's path: at least this many Rayleigh scale heights of radius
uniform vec3 uAtmoSunLight;    // the sun's intensity times the exposure, white balanced
uniform vec3 uAtmoSun;         // unit, toward the sun

float pmcRayleighPhase(float nu) { return 0.0596831 * (1.0 + nu * nu); }
float pmcMiePhase(float nu, float g) {
  float g2 = g * g;
  float k = 0.1193662 * (1.0 - g2) / (2.0 + g2);
  return k * (1.0 + nu * nu) / pow(max(1e-4, 1.0 + g2 - 2.0 * g * nu), 1.5);
}
float pmcChapmanUp(float x, float mu) {
  float a = mu * sqrt(0.5 * x);
  return sqrt(6.2831853 * x) / (2.3193 * a + sqrt(1.52 * a * a + 4.0));
}
// metres of air at ground density from height h along zenith cosine mu to infinity, the
// Chapman function taken for at least xMin scale heights of radius
float pmcSlantDepth(float h, float mu, float H, float xMin) {
  float r = uAtmoR + h;
  float x = max(r / H, xMin);
  if (mu >= 0.0) return H * exp(-h / H) * pmcChapmanUp(x, mu);
  float s = sqrt(max(0.0, 1.0 - mu * mu));
  float ht = h - r * mu * mu / (1.0 + s);
  float tangent = 2.0 * H * exp(min(50.0, -ht / H)) * sqrt(1.5707963 * max(r * s / H, xMin));
  return max(0.0, tangent - H * exp(-h / H) * pmcChapmanUp(x, -mu));
}
// the optical depth toward the sun from height h, the sun at zenith cosine mu
vec3 pmcSunDepth(float h, float mu) {
  return uAtmoRayleighExt * pmcSlantDepth(h, mu, uAtmoRayleighH, uAtmoSunPathX)
       + uAtmoMieExt * pmcSlantDepth(h, mu, uAtmoMieH, uAtmoSunPathX * uAtmoRayleighH / uAtmoMieH);
}
// the span of the ray of zenith cosine mu from the camera in the shell: (enter, exit, ground
// hit or -1); enter = exit = 0 when it misses
vec3 pmcRaySpan(float mu) {
  float h = uAtmoCamH;
  float R = uAtmoR;
  float b = (R + h) * mu;
  float dTop = b * b - (h - uAtmoTop) * (2.0 * R + h + uAtmoTop);
  if (dTop < 0.0) return vec3(0.0, 0.0, -1.0);
  float q = sqrt(dTop);
  float tExit = -b + q;
  if (tExit <= 0.0) return vec3(0.0, 0.0, -1.0);
  float tEnter = max(0.0, -b - q);
  float dGround = b * b - h * (2.0 * R + h);
  float tGround = -1.0;
  if (mu < 0.0 && dGround >= 0.0) {
    float tg = -b - sqrt(dGround);
    if (tg > 0.0 && tg < tExit) tGround = tg;
  }
  return vec3(tEnter, tExit, tGround);
}
// single scattering from t0 to t1 along dir (unit): the light (times the sun's) and the
// transmittance
void pmcScatter(vec3 dir, float t0, float t1, int samples, out vec3 light, out vec3 trans) {
  vec3 cam = uAtmoUp * (uAtmoR + uAtmoCamH);
  float dt = (t1 - t0) / float(samples);
  float nu = dot(dir, uAtmoSun);
  float pr = pmcRayleighPhase(nu);
  float pm = pmcMiePhase(nu, uAtmoMieG);
  vec3 depth = vec3(0.0);
  light = vec3(0.0);
  for (int i = 0; i < ${Math.max(SKY_SAMPLES, AERIAL_SAMPLES)}; i++) {
    if (i >= samples) break;
    float t = t0 + (float(i) + 0.5) * dt;
    vec3 p = cam + dir * t;
    float r = length(p);
    float h = max(r - uAtmoR, 0.0);
    float rhoR = exp(-h / uAtmoRayleighH);
    float rhoM = exp(-h / uAtmoMieH);
    vec3 ext = uAtmoRayleighExt * rhoR + uAtmoMieExt * rhoM;
    float muS = dot(p, uAtmoSun) / r;
    vec3 toSun = pmcSunDepth(h, muS);
    vec3 s = uAtmoRayleigh * (rhoR * pr) + uAtmoMie * (rhoM * pm);
    light += exp(-(depth + 0.5 * ext * dt) - toSun) * s * dt;
    depth += ext * dt;
  }
  light *= uAtmoSunLight;
  trans = exp(-depth);
}
vec3 pmcExposure(vec3 l) { return 1.0 - exp(-l); }
vec3 pmcAerialPerspective(vec3 colour, vec3 rel) {
  if (uAtmoOn < 0.5) return colour;
  float d = length(rel);
  if (d <= 0.0) return colour;
  vec3 dir = rel / d;
  vec3 span = pmcRaySpan(dot(dir, uAtmoUp));
  float t1 = min(d, span.y);
  if (t1 <= span.x) return colour;
  vec3 light;
  vec3 trans;
  // a step per half scale height, at most AERIAL_SAMPLES: near terrain costs one or two
  int n = int(clamp(ceil(2.0 * (t1 - span.x) / uAtmoRayleighH), 1.0, ${f(AERIAL_SAMPLES)}));
  pmcScatter(dir, span.x, t1, n, light, trans);
  // through SURFACE_SCATTER of the air (atmosphereModel.ts)
  return colour * pow(trans, vec3(${f(SURFACE_SCATTER)})) + pmcExposure(${f(SURFACE_SCATTER)} * light);
}
`;

const SKY_VERTEX = /* glsl */ `
varying vec3 vDir;
void main() {
  // the view ray through this corner: a point of the near plane, turned into the planet frame
  // (the camera sits at the render origin, so the view matrix is a rotation)
  vec4 near = inverse(projectionMatrix) * vec4(position.xy, -1.0, 1.0);
  vDir = transpose(mat3(viewMatrix)) * (near.xyz / near.w);
  gl_Position = vec4(position.xy, 1.0, 1.0); // at the far plane: behind everything drawn
}
`;

const SKY_FRAGMENT = /* glsl */ `
${ATMOSPHERE_GLSL}
varying vec3 vDir;
#include <common>
void main() {
  vec3 dir = normalize(vDir);
  float mu = dot(dir, uAtmoUp);
  vec3 span = pmcRaySpan(mu);
  bool bent = span.z >= 0.0;
  if (bent) {
    // the ground sphere where no terrain is drawn (not loaded, or lower than the datum): the sky
    // at the horizon in that direction, not a dark ground
    float h = uAtmoCamH;
    float muH = -sqrt(max(0.0, h * (2.0 * uAtmoR + h))) / (uAtmoR + h) + 1e-4;
    vec3 across = dir - uAtmoUp * mu;
    float l = length(across);
    across = l > 1e-6 ? across / l : normalize(cross(uAtmoUp, vec3(0.0, 0.0, 1.0)) + cross(uAtmoUp, vec3(1.0, 0.0, 0.0)));
    dir = across * sqrt(max(0.0, 1.0 - muH * muH)) + uAtmoUp * muH;
    span = pmcRaySpan(muH);
  }
  float end = span.y;
  vec3 light = vec3(0.0);
  vec3 trans = vec3(1.0);
  if (end > span.x) pmcScatter(dir, span.x, end, ${SKY_SAMPLES}, light, trans);
  if (!bent) {
    // the sun's disc, seen through the air along the sun's path (as the air it lights sees it)
    float nu = dot(dir, uAtmoSun);
    float t = clamp((nu - cos(${f(SUN_RADIUS * 1.3)})) / (cos(${f(SUN_RADIUS)}) - cos(${f(SUN_RADIUS * 1.3)})), 0.0, 1.0);
    vec3 sunTrans = exp(-pmcSunDepth(uAtmoCamH, dot(uAtmoUp, uAtmoSun)));
    light += t * t * (3.0 - 2.0 * t) * ${f(SUN_DISC)} * uAtmoSunLight * sunTrans;
  }
  vec3 colour = pmcExposure(light);
  colour += vec3(${SPACE.map(f).join(', ')}) * trans;
  gl_FragColor = vec4(colour, 1.0);
  #include <colorspace_fragment>
  // half a step of 8-bit noise against banding in the slow gradients
  float n = fract(52.9829189 * fract(dot(gl_FragCoord.xy, vec2(0.06711056, 0.00583715))));
  gl_FragColor.rgb += (n - 0.5) / 255.0;
}
`;

/** What `__pmc.sky()` shows and sets. */
export interface SkySettings {
  /** The atmosphere is wanted (it shows on planets that have one, not in the back-face mode). */
  atmosphere: boolean;
  /** The sun over the horizon under the camera: degrees clockwise from north, and up. */
  sunAzimuth: number;
  sunElevation: number;
}

export interface SkyState extends SkySettings {
  /** The planet's atmosphere, null for none. */
  kind: AtmosphereParams['kind'] | null;
  /** The sky and the aerial perspective are drawn now. */
  drawn: boolean;
  /** The unit direction toward the sun (planet frame) of the last frame. */
  sunDirection: V3;
}

/** The sky: the settings, the uniforms, the full-screen sky mesh. */
/** Where the sky panel's atmosphere checkbox is remembered between visits (`localStorage`). */
export const ATMOSPHERE_KEY = 'pmc.atmosphere';

/** The atmosphere checkbox as last left (`'off'` in `localStorage`: off); on by default. */
export function storedAtmosphere(): boolean {
  try {
    return globalThis.localStorage?.getItem(ATMOSPHERE_KEY) !== 'off';
  } catch {
    return true;
  }
}

/** Remembers the atmosphere checkbox (nothing where storage is unavailable). */
export function storeAtmosphere(on: boolean): void {
  try {
    globalThis.localStorage?.setItem(ATMOSPHERE_KEY, on ? 'on' : 'off');
  } catch {
    // private browsing or no storage: the setting lasts for this page only
  }
}

export class Atmosphere {
  readonly uniforms = createAtmosphereUniforms();
  readonly sky: THREE.Mesh<THREE.BufferGeometry, THREE.ShaderMaterial>;
  private params: AtmosphereParams | null = null;
  private suppressed = false;
  private readonly settings: SkySettings = { atmosphere: storedAtmosphere(), sunAzimuth: DEFAULT_SUN.azimuth, sunElevation: DEFAULT_SUN.elevation };
  private sun: V3 = [0, 1, 0];
  /** The camera of the last frame (planet frame), null before the first. */
  private camera: V3 | null = null;

  constructor() {
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(new Float32Array([-1, -1, 0, 3, -1, 0, -1, 3, 0]), 3));
    const material = new THREE.ShaderMaterial({
      vertexShader: SKY_VERTEX,
      fragmentShader: SKY_FRAGMENT,
      uniforms: this.uniforms,
      depthTest: true,
      depthWrite: false,
    });
    this.sky = new THREE.Mesh(g, material);
    this.sky.name = 'sky';
    this.sky.frustumCulled = false;
    // after the opaque terrain (renderOrder 0), before the transparent sea
    this.sky.renderOrder = 5;
    this.sky.visible = false;
  }

  /** The planet's atmosphere (null: none). */
  setPlanet(params: AtmosphereParams | null): void {
    this.params = params;
    const u = this.uniforms;
    if (params) {
      u.uAtmoR.value = params.groundRadius;
      u.uAtmoTop.value = params.top;
      u.uAtmoRayleigh.value.set(...params.rayleigh);
      u.uAtmoRayleighExt.value.set(...params.rayleighExtinction);
      u.uAtmoRayleighH.value = params.rayleighHeight;
      u.uAtmoMie.value.set(...params.mie);
      u.uAtmoMieExt.value.set(...params.mieExtinction);
      u.uAtmoMieH.value = params.mieHeight;
      u.uAtmoMieG.value = params.mieG;
      u.uAtmoSunPathX.value = params.sunPathX;
      u.uAtmoSunLight.value.set(...params.sun);
    }
    this.update();
  }

  /** Turns the atmosphere off whatever the settings say (the back-face and lighting-off test modes). */
  setSuppressed(suppressed: boolean): void {
    this.suppressed = suppressed;
    this.update();
  }

  /** Changes the settings given; returns them all. */
  set(settings: Partial<SkySettings>): SkySettings {
    if (settings.atmosphere !== undefined) this.settings.atmosphere = settings.atmosphere;
    if (settings.sunAzimuth !== undefined && Number.isFinite(settings.sunAzimuth)) {
      this.settings.sunAzimuth = ((settings.sunAzimuth % 360) + 360) % 360;
    }
    if (settings.sunElevation !== undefined && Number.isFinite(settings.sunElevation)) {
      this.settings.sunElevation = Math.max(-90, Math.min(90, settings.sunElevation));
    }
    this.update();
    if (this.camera) this.frame(this.camera);
    return { ...this.settings };
  }

  /** Whether the sky and the aerial perspective are drawn. */
  drawn(): boolean {
    return this.params !== null && this.settings.atmosphere && !this.suppressed;
  }

  /** The planet's atmosphere, null for none. */
  kind(): AtmosphereParams['kind'] | null {
    return this.params?.kind ?? null;
  }

  state(): SkyState {
    return { ...this.settings, kind: this.params?.kind ?? null, drawn: this.drawn(), sunDirection: [...this.sun] };
  }

  /**
   * A frame with the camera at `camera` (planet frame, f64): the sun over the horizon under it,
   * the camera's place in the shell. Returns the sun's direction.
   */
  frame(camera: V3): V3 {
    this.camera = [camera[0], camera[1], camera[2]];
    const enu = enuAt(camera);
    this.sun = sunDirection(enu, this.settings.sunAzimuth, this.settings.sunElevation);
    const u = this.uniforms;
    u.uAtmoSun.value.set(...this.sun);
    u.uAtmoUp.value.set(...enu.up);
    if (this.params) u.uAtmoCamH.value = Math.max(1e-3, length(camera) - this.params.groundRadius);
    return this.sun;
  }

  private update(): void {
    const on = this.drawn();
    this.uniforms.uAtmoOn.value = on ? 1 : 0;
    this.sky.visible = on;
  }

  dispose(): void {
    this.sky.geometry.dispose();
    this.sky.material.dispose();
  }
}
