// GLSL sources of the terrain and sea materials (three.js ShaderMaterial, GLSL ES 3 through
// three's prefix). Render space is the planet frame translated so that the camera sits at the
// origin (floating origin): directions are planet-frame directions, and the view vector of a
// fragment is minus its render-space position.

/**
 * 3D value noise with a lattice period of 289 cells in every axis (a permutation polynomial
 * mod 289, exact in f32). Sampled at `(origin mod P) + position` with P a multiple of the period,
 * it is continuous across chunks while every coordinate stays small.
 */
const NOISE = /* glsl */ `
float pmcPermute(float x) { return mod((34.0 * x + 1.0) * x, 289.0); }
float pmcHash(vec3 c) {
  c = mod(c, 289.0);
  return pmcPermute(pmcPermute(pmcPermute(c.x) + c.y) + c.z) / 289.0;
}
float pmcValueNoise(vec3 p) {
  vec3 i = floor(p);
  vec3 f = fract(p);
  vec3 w = f * f * (3.0 - 2.0 * f);
  float n000 = pmcHash(i);
  float n100 = pmcHash(i + vec3(1.0, 0.0, 0.0));
  float n010 = pmcHash(i + vec3(0.0, 1.0, 0.0));
  float n110 = pmcHash(i + vec3(1.0, 1.0, 0.0));
  float n001 = pmcHash(i + vec3(0.0, 0.0, 1.0));
  float n101 = pmcHash(i + vec3(1.0, 0.0, 1.0));
  float n011 = pmcHash(i + vec3(0.0, 1.0, 1.0));
  float n111 = pmcHash(i + vec3(1.0, 1.0, 1.0));
  return mix(
    mix(mix(n000, n100, w.x), mix(n010, n110, w.x), w.y),
    mix(mix(n001, n101, w.x), mix(n011, n111, w.x), w.y),
    w.z);
}
// three octaves at f, 2f, 4f: all periods divide 289 / f
float pmcFbm(vec3 p) {
  return 0.5714 * pmcValueNoise(p) + 0.2857 * pmcValueNoise(p * 2.0 + 17.0)
       + 0.1429 * pmcValueNoise(p * 4.0 + 41.0);
}
`;

/** Cells of the noise lattice per period: the period in metres is NOISE_PERIOD_CELLS / frequency. */
export const NOISE_PERIOD_CELLS = 289;

export const terrainVertex = /* glsl */ `
attribute vec4 aColor;
attribute float aHeight;
attribute float aWaterDepth;
attribute float aMaterial;
uniform vec3 uOrigin;     // chunk origin (f32: used for directions only)
uniform vec3 uOriginMod;  // chunk origin modulo the noise period (computed in f64)
uniform float uNoiseFreq;
varying vec3 vColor;
varying float vHeight;
varying float vWater;
varying vec3 vNormal;
varying vec3 vNoisePos;
varying vec3 vUp;
varying vec3 vRel;
#include <common>
#include <logdepthbuf_pars_vertex>
void main() {
  vec4 world = modelMatrix * vec4(position, 1.0);
  vRel = world.xyz;
  vColor = aColor.rgb;
  vHeight = aHeight;
  vWater = aWaterDepth;
  vNormal = normal;
  vNoisePos = (uOriginMod + position) * uNoiseFreq;
  vUp = normalize(uOrigin + position);
  gl_Position = projectionMatrix * viewMatrix * world;
  #include <logdepthbuf_vertex>
}
`;

export const terrainFragment = /* glsl */ `
uniform vec3 uSunDir;
uniform vec3 uPaletteA;
uniform vec3 uPaletteB;
uniform float uPaletteStrength;
uniform float uBandHeight;   // metres: scale of the height bands
uniform float uSnowHeight;   // metres above the datum where snow starts
uniform float uSnowAmount;   // 0..1
uniform vec3 uWaterShallow;
uniform vec3 uWaterDeep;
uniform float uWaterScale;   // metres of water that absorb most light
uniform float uDebugFace;
uniform vec3 uFaceColour;
uniform vec3 uSkyColour;
uniform float uFogDistance;
uniform float uBackfaceFlag; // test mode: back faces (the inside of the solid) in pure magenta
varying vec3 vColor;
varying float vHeight;
varying float vWater;
varying vec3 vNormal;
varying vec3 vNoisePos;
varying vec3 vUp;
varying vec3 vRel;
#include <common>
#include <logdepthbuf_pars_fragment>
${NOISE}
void main() {
  #include <logdepthbuf_fragment>
  if (uBackfaceFlag > 0.5 && !gl_FrontFacing) {
    #ifdef USE_LOGDEPTHBUF
    // 0.2 % farther: where a back face meets a front face at a silhouette (the same edge, the
    // same depth) the front face wins; the inside seen through a crack is far behind anyway
    gl_FragDepth = min(1.0, gl_FragDepth + log2(1.002) * logDepthBufFC * 0.5);
    #endif
    gl_FragColor = vec4(1.0, 0.0, 1.0, 1.0);
    return;
  }
  vec3 n = normalize(vNormal);
  vec3 up = normalize(vUp);
  float noise = pmcFbm(vNoisePos);
  vec3 base = vColor;
  // the planet's two-colour blend, mixed by noise that is continuous across chunks
  vec3 blend = mix(uPaletteA, uPaletteB, smoothstep(0.25, 0.75, noise));
  base = mix(base, base * blend, uPaletteStrength); // palette normalised to mean luminance 1
  // height bands: low ground a touch darker, high ground a touch brighter
  float band = clamp(vHeight / max(uBandHeight, 1e-3), -1.0, 1.0);
  base *= 0.9 + 0.18 * band;
  // snow on gentle slopes above the snow line, its edge broken up by the noise
  float gentle = smoothstep(0.55, 0.8, dot(n, up));
  float snow = smoothstep(uSnowHeight, uSnowHeight + 0.15 * uBandHeight,
                          vHeight + (noise - 0.5) * 0.2 * uBandHeight);
  base = mix(base, vec3(0.92, 0.94, 0.97), snow * gentle * uSnowAmount);
  if (uDebugFace > 0.5) base = uFaceColour * (0.75 + 0.25 * noise);

  // sun and sky light
  float diffuse = max(dot(n, uSunDir), 0.0);
  float sky = 0.5 + 0.5 * dot(n, up);
  vec3 lit = base * (0.15 + 0.2 * sky + 0.72 * diffuse);

  // under the sea: absorbed along the path through the water
  if (vWater > 0.0) {
    vec3 v = normalize(-vRel);
    float cosView = max(abs(dot(v, up)), 0.2);
    float path = vWater * 0.5 * (1.0 + 1.0 / cosView);
    float k = 1.0 - exp(-path / max(uWaterScale, 1e-3));
    lit = mix(lit * uWaterShallow, uWaterDeep, k);
  }
  // a little aerial perspective far away
  float fog = 1.0 - exp(-length(vRel) / max(uFogDistance, 1.0));
  lit = mix(lit, uSkyColour, 0.35 * fog);
  gl_FragColor = vec4(lit, 1.0);
  #include <colorspace_fragment>
}
`;

export const seaVertex = /* glsl */ `
varying vec3 vNormal;
varying vec3 vRel;
#include <common>
#include <logdepthbuf_pars_vertex>
void main() {
  vec4 world = modelMatrix * vec4(position, 1.0);
  vRel = world.xyz;
  vNormal = normal;
  gl_Position = projectionMatrix * viewMatrix * world;
  #include <logdepthbuf_vertex>
}
`;

export const seaFragment = /* glsl */ `
uniform vec3 uSunDir;
uniform vec3 uSeaColour;
uniform vec3 uSkyColour;
uniform float uFogDistance;
varying vec3 vNormal;
varying vec3 vRel;
#include <common>
#include <logdepthbuf_pars_fragment>
void main() {
  #include <logdepthbuf_fragment>
  vec3 n = normalize(vNormal);
  if (!gl_FrontFacing) n = -n;
  vec3 v = normalize(-vRel);
  float cosV = clamp(dot(n, v), 0.0, 1.0);
  float fresnel = 0.02 + 0.98 * pow(1.0 - cosV, 5.0);
  float diffuse = max(dot(n, uSunDir), 0.0);
  vec3 h = normalize(uSunDir + v);
  float spec = pow(max(dot(n, h), 0.0), 120.0) * step(0.0, diffuse);
  vec3 colour = uSeaColour * (0.35 + 0.65 * diffuse);
  colour = mix(colour, uSkyColour, fresnel * 0.8) + vec3(1.0, 0.97, 0.9) * spec * 0.8;
  // nearly clear looking down, opaque at grazing angles
  float alpha = clamp(0.35 + 0.55 * pow(1.0 - cosV, 2.0) + spec, 0.0, 0.96);
  float fog = 1.0 - exp(-length(vRel) / max(uFogDistance, 1.0));
  colour = mix(colour, uSkyColour, 0.35 * fog);
  gl_FragColor = vec4(colour, alpha);
  #include <colorspace_fragment>
}
`;

export const NOISE_GLSL = NOISE;
