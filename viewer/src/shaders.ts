// GLSL sources of the terrain and sea materials (three.js ShaderMaterial, GLSL ES 3 through
// three's prefix). Render space is the planet frame translated so that the camera sits at the
// origin (floating origin): directions are planet-frame directions, and the view vector of a
// fragment is minus its render-space position.

import { ATMOSPHERE_GLSL } from './atmosphere';

/**
 * 3D value noise with a lattice period of 289 cells in every axis (a permutation polynomial
 * mod 289, exact in f32). Sampled at `(origin mod P) + position` with P a multiple of the period,
 * it is continuous across chunks while every coordinate stays small.
 */
const NOISE = /* glsl */ `
float pmcPermute(float x) { return mod((34.0 * x + 1.0) * x, 289.0); }
// A corner's hash is pmcPermute(pmcPermute(pmcPermute(x) + y) + z) / 289 of its lattice
// coordinates mod 289; the eight corners share their x and (x, y) terms, computed once here
// (2 + 4 + 8 permutations instead of 24: a software renderer runs the arithmetic as written, and
// the noise is most of the terrain's cost per pixel).
float pmcValueNoise(vec3 p) {
  vec3 i = floor(p);
  vec3 f = fract(p);
  vec3 w = f * f * (3.0 - 2.0 * f);
  vec3 c0 = mod(i, 289.0);
  vec3 c1 = mod(i + 1.0, 289.0);
  float x0 = pmcPermute(c0.x);
  float x1 = pmcPermute(c1.x);
  float y00 = pmcPermute(x0 + c0.y);
  float y10 = pmcPermute(x1 + c0.y);
  float y01 = pmcPermute(x0 + c1.y);
  float y11 = pmcPermute(x1 + c1.y);
  float n000 = pmcPermute(y00 + c0.z) / 289.0;
  float n100 = pmcPermute(y10 + c0.z) / 289.0;
  float n010 = pmcPermute(y01 + c0.z) / 289.0;
  float n110 = pmcPermute(y11 + c0.z) / 289.0;
  float n001 = pmcPermute(y00 + c1.z) / 289.0;
  float n101 = pmcPermute(y10 + c1.z) / 289.0;
  float n011 = pmcPermute(y01 + c1.z) / 289.0;
  float n111 = pmcPermute(y11 + c1.z) / 289.0;
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

/**
 * The terrain's logarithmic depth (three.js's, for a perspective camera), its varying sampled at
 * the centroid of the samples a triangle covers, not at the pixel's centre: with antialiasing a
 * fragment writes one depth for all its samples, and at a silhouette seen at a grazing angle the
 * depth extrapolated to the pixel's centre lay far off the triangle, so the sky or the far side of
 * a ridge won samples of the pixels along it (dark dots along the silhouettes of small relief
 * from 10 km, `docs/images/earth-10km.png`).
 */
const LOG_DEPTH_PARS = /* glsl */ `
#ifdef USE_LOGARITHMIC_DEPTH_BUFFER
centroid varying float vFragDepth;
#endif
`;

/** Cells of the noise lattice per period: the period in metres is NOISE_PERIOD_CELLS / frequency. */
export const NOISE_PERIOD_CELLS = 289;

/**
 * The place noise's lowest octave, relative to its frequency (the material lines' jitter). The
 * chunk origins are taken modulo a period of the place noise (planetParams.ts) that this octave's
 * lattice repeats over too: with the period of the first octave alone, a quarter of it wrapped
 * 72.25 cells of the jitter's lattice, which then differed from chunk to chunk, and the shore's
 * and the snow's lines moved when a place's level changed (ΔE 28, step 14).
 */
export const JITTER_SCALE = 0.25;

/**
 * The sea surface over what lies below it (`below`, linear RGB) at unit normal `n` seen along unit
 * `v` (toward the eye): the surface's colour and sky reflection (Fresnel) and the sun's glint,
 * blended over `below` by the surface's opacity (nearly clear looking down, opaque at grazing
 * angles), which is returned in `.a`. The terrain shader draws it over ground below the datum, the
 * sea disk where no ground lies behind the surface, so both look the same (and so do the tiles of
 * the 3D Tiles mode: tilesMode.ts).
 */
export const SEA_SURFACE = /* glsl */ `
vec4 pmcSeaSurface(vec3 below, vec3 n, vec3 v) {
  float cosV = clamp(dot(n, v), 0.0, 1.0);
  float fresnel = 0.02 + 0.98 * pow(1.0 - cosV, 5.0);
  float diffuse = max(dot(n, uSunDir), 0.0);
  vec3 hv = normalize(uSunDir + v);
  // the glint: a small bright core and a faint sheen round it (waves spread it); one broad
  // lobe washed a kilometres-wide disk of the sea out to white seen from high up
  float nh = max(dot(n, hv), 0.0);
  float spec = (pow(nh, 900.0) + 0.06 * pow(nh, 90.0)) * step(0.0, diffuse);
  vec3 colour = uSeaColour * (0.35 + 0.65 * diffuse);
  colour = mix(colour, uSkyColour, fresnel * 0.8) + vec3(1.0, 0.97, 0.9) * spec * 0.8;
  float alpha = clamp(0.35 + 0.55 * pow(1.0 - cosV, 2.0) + spec, 0.0, 0.96);
  return vec4(mix(below, colour, alpha), alpha);
}
`;

export const terrainVertex = /* glsl */ `
attribute vec4 aColor;
attribute float aHeight;
attribute float aWaterDepth;
attribute float aMaterial;
attribute vec3 aPosHigh;  // the vertex's planet-frame place, high and low f32 parts (frames.ts)
attribute vec3 aPosLow;
uniform vec3 uEyeHigh;    // the eye's place, split the same way
uniform vec3 uEyeLow;
uniform vec3 uOrigin;     // chunk origin (f32: used for directions only)
uniform vec3 uOriginMod;  // chunk origin modulo the noise period (computed in f64)
uniform float uNoiseFreq;
uniform vec3 uOriginModDetail; // chunk origin modulo the detail noise's period (computed in f64)
uniform float uDetailFreq;
varying vec3 vColor;
varying float vHeight;
varying float vWater;
varying vec3 vNormal;
varying vec3 vNoisePos;
varying vec3 vUp;
varying vec3 vRel;
varying vec3 vDetailPos;
#include <common>
${LOG_DEPTH_PARS}
void main() {
  // relative to the eye from the high and low parts, not modelMatrix * position: every copy of
  // a border vertex (one place, chunks of other origins) then lands on the same bits
  vec4 world = vec4((aPosHigh - uEyeHigh) + (aPosLow - uEyeLow), 1.0);
  vRel = world.xyz;
  vDetailPos = (uOriginModDetail + position) * uDetailFreq;
  vColor = aColor.rgb;
  vHeight = aHeight;
  vWater = aWaterDepth;
  vNormal = normal;
  vNoisePos = (uOriginMod + position) * uNoiseFreq;
  vUp = normalize(uOrigin + position);
  gl_Position = projectionMatrix * viewMatrix * world;
  #ifdef USE_LOGARITHMIC_DEPTH_BUFFER
  vFragDepth = 1.0 + gl_Position.w;
  #endif
}
`;

export const terrainFragment = /* glsl */ `
uniform vec3 uSunDir;
uniform float uDebugFace;
uniform vec3 uFaceColour;
uniform vec3 uSkyColour;
uniform float uFogDistance;
uniform float uBackfaceFlag; // test mode: back faces (the inside of the solid) in pure magenta
uniform float uLighting;     // 1: sun and sky light; 0 (test mode): the albedo alone, no haze
uniform float uNoiseFreq;    // the place noise: cycles per metre (vNoisePos)
uniform float uDetailFreq;   // the detail noise near the ground: cycles per metre (vDetailPos)
uniform float uMacroFreq;    // the large-scale noise: cells per unit of direction
uniform float uDatum;        // radius of the datum, metres
// the material model (viewer/src/materials.ts): two colours per material, indexed as
// MATERIAL_SLOTS (deep, shelf, shore, low, forest, dry, rock, snow, dark, ice); heights in metres
// above the datum
uniform vec3 uMatA[10];
uniform vec3 uMatB[10];
uniform vec4 uMatHeights;    // shelf depth, shore height, forest-from height, tree line (of the snow line)
uniform vec4 uMatSnow;       // snow line at the equator, k, q, p: line (1 - k sin^(2q) lat)^p
uniform vec4 uMatShares;     // forest share, dry share, dark height, dark share
uniform vec4 uMatSlopes;     // rock below this cos(slope), snow above it, ice from |sin lat|, line jitter (m)
uniform vec2 uMatExtra;      // lowest snow line, width of a height transition (m)
// the sea, decided per pixel from the interpolated height
uniform float uHasSea;       // the planet has a sea at the datum
uniform float uWater;        // draw water where the height is below the datum (0: test mode)
uniform vec3 uWaterShallow;
uniform vec3 uWaterDeep;
uniform float uWaterScale;   // metres of water that absorb most light
uniform vec3 uSeaColour;
// imagery draped by latitude and longitude (viewer/src/imagery.ts)
uniform sampler2D uImagery;
uniform float uHasImagery;
uniform vec4 uImageryExtent; // west, east, south, north, radians (cell edges)
uniform float uImageryCell;  // metres of one picture cell on the ground
// an elevation model's relief (viewer/src/relief.ts): the materials' height where a pixel spans
// a good part of a data cell, the same at every level of detail
uniform sampler2D uRelief;   // one f32 channel, the data's metres, row 0 the southernmost
uniform float uHasRelief;
uniform vec4 uReliefAxes;    // longitude of column 0, between columns, latitude of row 0, between rows (radians)
uniform vec4 uReliefGrid;    // columns, rows, wraps (1), rows clamped past the south (1) and north (2) edges
uniform vec2 uReliefScale;   // metres of the planet per metre of the data, metres of a data cell on the ground
varying vec3 vColor;
varying float vHeight;
varying float vWater;
varying vec3 vNormal;
varying vec3 vNoisePos;
varying vec3 vUp;
varying vec3 vRel;
varying vec3 vDetailPos;
#include <common>
${LOG_DEPTH_PARS}
#ifdef USE_LOGARITHMIC_DEPTH_BUFFER
uniform float logDepthBufFC;
#endif
${NOISE}
${SEA_SURFACE}
${ATMOSPHERE_GLSL}
// Weight of a noise octave whose coordinate moves by fw cells per pixel: 1 while a cell spans
// several pixels, 0 where it would alias.
float pmcResolved(float fw) { return 1.0 - smoothstep(0.12, 0.45, fw); }
// Octaves at f, 2f, ... 2^(n-1) f of value noise around 0.5, each faded out below the pixel;
// fw: cells of the first octave per pixel.
float pmcFiltered(vec3 q, int octaves, float fw) {
  float sum = 0.0;
  float amp = 0.5;
  float scale = 1.0;
  for (int i = 0; i < 6; i++) {
    if (i >= octaves) break;
    // (an octave finer than the pixel weighs 0, and so does every finer one: not evaluated)
    float weight = pmcResolved(fw * scale);
    if (weight <= 0.0) break;
    sum += amp * weight * (pmcValueNoise(q * scale + float(i) * 17.0) - 0.5);
    amp *= 0.5;
    scale *= 2.0;
  }
  return 0.5 + sum;
}
// Variation at every scale between kilometres and metres: octaves of value noise of the unit
// direction from cells of firstCell metres down to 6 m, each faded out as its cells shrink from
// 32 to 8 pixels (mpp metres per pixel: patches, never grain) and the coarsest first, so a view
// costs only the octaves it shows. Around 0.5. (Finer than 6 m the f32 direction would jitter the
// lattice; the detail noise takes over.)
float pmcAllScales(vec3 up, float firstCell, float mpp) {
  float sum = 0.0;
  float amp = 0.5;
  float cell = firstCell;
  for (int i = 0; i < 14; i++) {
    if (cell < 6.0) break;
    float fw = mpp / cell;
    // (an octave under 8 pixels weighs 0, and so does every finer one: not evaluated)
    if (!(fw < 0.125)) break;
    sum += amp * (1.0 - smoothstep(0.03125, 0.125, fw)) * (pmcValueNoise(up * (uDatum / cell) + float(i) * 13.7) - 0.5);
    amp *= 0.85;
    cell *= 0.5;
  }
  return 0.5 + sum;
}
vec3 pmcMat(int i, float t) { return mix(uMatA[i], uMatB[i], t); }
// 0 below the line, 1 above it, a smooth step of half-width w; lines at +-1e30 are absent.
float pmcAbove(float x, float line, float w) {
  if (line > 1e29) return 0.0;
  if (line < -1e29) return 1.0;
  return smoothstep(line - w, line + w, x);
}
// A share (0..1) of the places by a noise value around 0.5.
float pmcShare(float n, float share) {
  if (share <= 0.0) return 0.0;
  float th = 0.5 + 0.3 * (0.5 - share);
  return smoothstep(th - 0.03, th + 0.03, n);
}
// The albedo of the ground at height h (m above the datum) along the unit direction up, with
// cos(slope) slope counting slopeWeight (0..1), palette mix t, line jitter jit (-1..1),
// large-scale noises m1, m2. Height lines are smooth steps: a place's colour hardly changes with
// the level drawn.
vec3 pmcGround(float h, vec3 up, float slope, float t, float jit, float m1, float m2, float slopeWeight) {
  float w = uMatExtra.y;
  if (uHasSea > 0.5 && h < 0.0) {
    float deep = uMatHeights.x > 1e29 ? 0.0 : smoothstep(0.7 * uMatHeights.x, 1.3 * uMatHeights.x, -h);
    return mix(pmcMat(1, t), pmcMat(0, t), deep);
  }
  float hj = h + jit * uMatSlopes.w;
  float s2 = up.y * up.y;
  float snowLine = uMatSnow.x > 1e29 ? 1e30
    : max(uMatExtra.x, uMatSnow.x * pow(max(0.0, 1.0 - uMatSnow.y * pow(s2, uMatSnow.z)), uMatSnow.w));
  float treeLine = snowLine > 1e29 || uMatHeights.w > 1e29 ? 1e30 : uMatHeights.w * snowLine;
  // lowlands: grass, forest in large patches and above the forest line
  vec3 c = pmcMat(3, t);
  float forest = max(pmcShare(m1, uMatShares.x), pmcAbove(hj, uMatHeights.z, w));
  c = mix(c, pmcMat(4, t), forest);
  // deserts, mostly in the subtropics (|sin lat| near 0.42), below 0.6 of the snow line
  float subtropics = 1.0 - smoothstep(0.0, 0.25, abs(abs(up.y) - 0.42));
  float dry = pmcShare(m2 + 0.1 * subtropics, uMatShares.y) * (1.0 - pmcAbove(hj, 0.6 * snowLine, w));
  c = mix(c, pmcMat(5, t), dry);
  // the dark material: low basins (maria, canyon floors) and patches (dunes)
  float dark = max(1.0 - pmcAbove(hj, uMatShares.z, w), pmcShare(m2, uMatShares.w));
  c = mix(c, pmcMat(8, t), dark);
  // sand on the shore
  float sw = 0.5 * uMatHeights.y;
  float shore = uMatHeights.y > 0.0 ? 1.0 - smoothstep(uMatHeights.y - sw, uMatHeights.y + sw, h + 0.3 * jit * uMatHeights.y) : 0.0;
  c = mix(c, pmcMat(2, t), shore);
  // rock above the tree line and on steep slopes
  float steep = (1.0 - smoothstep(uMatSlopes.x - 0.1, uMatSlopes.x + 0.1, slope)) * slopeWeight;
  c = mix(c, pmcMat(6, t), max(pmcAbove(hj, treeLine, w), steep));
  // snow above the snow line and polar ice, on gentle slopes
  float gentle = 1.0 - (1.0 - smoothstep(uMatSlopes.y - 0.1, uMatSlopes.y + 0.1, slope)) * slopeWeight;
  c = mix(c, pmcMat(7, t), pmcAbove(hj, snowLine, w) * gentle);
  float ice = uMatSlopes.z > 1.0 ? 0.0 : smoothstep(uMatSlopes.z - 0.02, uMatSlopes.z + 0.02, abs(up.y) + 0.03 * jit);
  c = mix(c, pmcMat(9, t), ice * gentle);
  return c;
}
// The picture's colour at latitude lat and longitude lon (radians, of the unit direction up as
// main computes them) (linear RGB), its weight in .a (0 outside the extent). Longitude per pixel, modulo 360 into the extent; the texture's gradients taken from
// whichever of two longitude origins has no wrap inside the pixel's quad (no seam at the
// antimeridian).
vec4 pmcImagery(float lat, float lon) {
  float span = uImageryExtent.y - uImageryExtent.x;
  float u = mod(lon - uImageryExtent.x, 2.0 * PI) / span;
  float u2 = mod(lon - uImageryExtent.x + PI, 2.0 * PI) / span;
  float v = (lat - uImageryExtent.z) / (uImageryExtent.w - uImageryExtent.z);
  vec2 gx = vec2(dFdx(u), dFdx(v));
  vec2 gy = vec2(dFdy(u), dFdy(v));
  float gx2 = dFdx(u2);
  float gy2 = dFdy(u2);
  if (abs(gx2) + abs(gy2) < abs(gx.x) + abs(gy.x)) {
    gx.x = gx2;
    gy.x = gy2;
  }
  float inside = step(u, 1.0) * step(0.0, v) * step(v, 1.0);
  vec3 c = textureGrad(uImagery, vec2(u, v), gx, gy).rgb;
  return vec4(c, inside);
}
// The relief's height (metres above the datum) at latitude lat and longitude lon (radians),
// bilinear in column and row as relief.ts's reliefHeightAt; .y 1 on the grid, 0 off a regional
// one; .z the cosine of its slope (from the bilinear patch's gradient, metres per metre along the
// parallel and the meridian).
vec4 pmcRelief(float lat, float lon) {
  float w = uReliefGrid.x;
  float h = uReliefGrid.y;
  float x = mod(lon - uReliefAxes.x, 2.0 * PI) / uReliefAxes.y;
  float y = (lat - uReliefAxes.z) / uReliefAxes.w;
  float inside = 1.0;
  float clampBits = uReliefGrid.w;
  if (y < 0.0) {
    if (mod(clampBits, 2.0) < 0.5 && y < -1e-3) inside = 0.0;
    y = 0.0;
  } else if (y > h - 1.0) {
    if (clampBits < 1.5 && y > h - 1.0 + 1e-3) inside = 0.0;
    y = h - 1.0;
  }
  if (uReliefGrid.z > 0.5) {
    x = mod(x, w);
  } else if (x > w - 1.0) {
    if (x > w - 1.0 + 1e-3) inside = 0.0;
    x = w - 1.0;
  }
  float c0 = min(floor(x), w - 1.0);
  float r0 = min(floor(y), h - 1.0);
  float c1 = uReliefGrid.z > 0.5 ? mod(c0 + 1.0, w) : min(c0 + 1.0, w - 1.0);
  float r1 = min(r0 + 1.0, h - 1.0);
  float fx = x - c0;
  float fy = y - r0;
  float s0 = texelFetch(uRelief, ivec2(int(c0), int(r0)), 0).r;
  float s1 = texelFetch(uRelief, ivec2(int(c1), int(r0)), 0).r;
  float n0 = texelFetch(uRelief, ivec2(int(c0), int(r1)), 0).r;
  float n1 = texelFetch(uRelief, ivec2(int(c1), int(r1)), 0).r;
  float south = mix(s0, s1, fx);
  float north = mix(n0, n1, fx);
  float cellX = uReliefAxes.y * uDatum * max(cos(lat), 1e-3);
  float cellY = uReliefAxes.w * uDatum;
  float gx = mix(s1 - s0, n1 - n0, fy) * uReliefScale.x / max(cellX, 1e-6);
  float gy = mix(n0 - s0, n1 - s1, fx) * uReliefScale.x / max(cellY, 1e-6);
  return vec4(mix(south, north, fy) * uReliefScale.x, inside, inversesqrt(1.0 + gx * gx + gy * gy), 0.0);
}
void main() {
  #ifdef USE_LOGARITHMIC_DEPTH_BUFFER
  gl_FragDepth = log2(vFragDepth) * logDepthBufFC * 0.5;
  // the depth's change from this pixel to the next (outside the branch below: derivatives need
  // the whole pixel quad)
  float depthSlope = fwidth(gl_FragDepth);
  #endif
  if (uBackfaceFlag > 0.5 && !gl_FrontFacing) {
    #ifdef USE_LOGARITHMIC_DEPTH_BUFFER
    // 0.2 % farther: where a back face meets a front face at a silhouette (the same edge, the
    // same depth) the front face wins; the inside seen through a crack is far behind anyway.
    // (three.js's define; under its former name, USE_LOGDEPTHBUF, this offset was compiled out
    // and back faces won half the samples along every silhouette in the test mode.) And two
    // pixels' depth slope farther (a slope-scaled offset, as polygon offset's factor): a fragment
    // writes one depth, its centroid's, for all its antialiasing samples, and where the ground
    // is seen edge-on (a ridge's silhouette from 50 m) the depth changes by more than 0.2 %
    // inside one pixel, and a back face behind the silhouette won a sample of it (a tinted pixel
    // in step 9's 50 m view; none since)
    gl_FragDepth = min(1.0, gl_FragDepth + log2(1.002) * logDepthBufFC * 0.5 + 2.0 * depthSlope);
    #endif
    gl_FragColor = vec4(1.0, 0.0, 1.0, 1.0);
    return;
  }
  vec3 n = normalize(vNormal);
  #ifdef PMC_PLAIN
  // test mode (a program of its own): a grey green lit by the sun, never the back faces'
  // magenta, a sky's or the test background's colour
  gl_FragColor = vec4(vec3(0.42, 0.5, 0.38) * (0.45 + 0.55 * max(dot(n, uSunDir), 0.0)), 1.0);
  #else
  vec3 up = normalize(vUp);
  float slope = dot(n, up);
  // (the imagery's rock on steep ground goes by the mesh's slope: the relief's, at full weight
  // from afar, mixed rock into a picture coarser than the pixels, 9/255 off it in step 13)
  float meshSlope = slope;
  // the place's latitude and longitude, for the relief and the imagery
  float lat = asin(clamp(up.y, -1.0, 1.0));
  float lon = atan(up.x, up.z);
  // The pixel's footprint, metres: its distance times the angle a pixel subtends (the change of
  // the view ray's direction from one pixel to the next, whatever the surface's orientation). It
  // depends on the view alone, never on the triangles drawn, so every filter below gives a place
  // the same colour at every level of detail.
  vec3 ray = normalize(vRel);
  float metresPerPixel = length(vRel) * max(length(dFdx(ray)), length(dFdy(ray)));
  // The height the materials and the sea go by: the mesh's, or, where a pixel spans more than a
  // few hundredths of a relief cell, the relief at the place (the same at every level, where a
  // coarse chunk's triangles pass hundreds of metres under a finer one's peaks, and draw the
  // material lines as polygons dozens of pixels wide)
  // and the slope: the mesh's counts less as the pixel grows past a tile (a coarse level smooths
  // it: its normals change with the level), the relief's as much as the relief resolves it
  float h = vHeight;
  float slopeWeight = 1.0 - smoothstep(0.1, 1.0, metresPerPixel * 2.0 * uNoiseFreq);
  if (uHasRelief > 0.5) {
    vec4 relief = pmcRelief(lat, lon);
    float far = smoothstep(0.02, 0.08, metresPerPixel / max(uReliefScale.y, 1e-3)) * relief.y;
    h = mix(h, relief.x, far);
    slope = mix(slope, relief.z, far);
    slopeWeight = mix(slopeWeight, 1.0, far);
  }
  // the place's noises: fixed frequencies of the planet, filtered by the pixel's footprint, at
  // the height the materials go by (the mesh's moved up or down to the relief's): a coarse
  // level's surface lies metres under a fine one's, and the noise of the mesh's own place moved
  // the snow line's jitter with the level drawn (ΔE 27 at a snow patch's edge, step 14)
  vec3 noisePos = vNoisePos + up * ((h - vHeight) * uNoiseFreq);
  float meso = pmcFiltered(noisePos, 6, metresPerPixel * uNoiseFreq);
  float jit = 2.0 * (pmcFiltered(noisePos * ${JITTER_SCALE.toFixed(4)} + 31.0, 3, ${JITTER_SCALE.toFixed(4)} * metresPerPixel * uNoiseFreq) - 0.5) * 2.0;
  float m1 = pmcFiltered(up * uMacroFreq, 4, metresPerPixel * uMacroFreq / max(uDatum, 1.0));
  float m2 = pmcFiltered(up * (0.31 * uMacroFreq) + 53.0, 4, 0.31 * metresPerPixel * uMacroFreq / max(uDatum, 1.0));
  float detail = pmcFiltered(vDetailPos + up * ((h - vHeight) * uDetailFreq), 4, metresPerPixel * uDetailFreq);
  // variation from the picture's cells (or 0.3 % of the radius: 19 km on the Earth) down to 6 m,
  // where the tile-sized noise above is too fine to see and the picture too coarse
  float firstCell = uHasImagery > 0.5 ? uImageryCell : 0.003 * uDatum;
  float scales = pmcAllScales(up, firstCell, metresPerPixel);
  float t = clamp(0.5 + 2.5 * (meso - 0.5) + 2.5 * (scales - 0.5), 0.0, 1.0);
  vec3 base = pmcGround(h, up, slope, t, clamp(jit, -1.0, 1.0), m1, m2, slopeWeight);
  bool underwater = uHasSea > 0.5 && h < 0.0;
  // (sampled outside the branch: texture gradients need the whole pixel quad)
  vec4 img = uHasImagery > 0.5 ? pmcImagery(lat, lon) : vec4(0.0);
  if (uHasImagery > 0.5 && !underwater) {
    // metres per pixel against the picture's cell: below its resolution, the procedural detail
    float below = 1.0 - smoothstep(0.05, 0.5, metresPerPixel / max(uImageryCell, 1e-3));
    // below the picture's cells: lighter and drier or darker and greener patches at every scale
    float s = clamp(3.0 * (scales - 0.5), -1.0, 1.0);
    vec3 tint = s < 0.0 ? mix(vec3(1.0), vec3(0.78, 0.92, 0.74), -s) : mix(vec3(1.0), vec3(1.2, 1.12, 0.94), s);
    vec3 draped = img.rgb * mix(vec3(1.0), tint * (1.0 + 0.4 * (t - 0.5)), below);
    float steep = 1.0 - smoothstep(uMatSlopes.x - 0.06, uMatSlopes.x + 0.06, meshSlope);
    draped = mix(draped, pmcMat(6, t), 0.6 * steep * below);
    base = mix(base, draped, img.a);
  }
  // detail near the ground (mean 1: nothing from afar)
  base *= 1.0 + 0.3 * (detail - 0.5);
  if (uDebugFace > 0.5) base = uFaceColour * (0.75 + 0.25 * meso);

  vec3 lit = base;
  if (uLighting > 0.5) {
    float diffuse = max(dot(n, uSunDir), 0.0);
    float sky = 0.5 + 0.5 * dot(n, up);
    lit = base * (0.15 + 0.2 * sky + 0.72 * diffuse);
  }
  // the sea, where the ground is below the datum: absorbed along the path through the water,
  // under the surface that the sea disk draws where no ground is behind it
  if (underwater && uWater > 0.5) {
    vec3 v = normalize(-vRel);
    float cosView = max(abs(dot(v, up)), 0.2);
    float path = -h * 0.5 * (1.0 + 1.0 / cosView);
    float k = 1.0 - exp(-path / max(uWaterScale, 1e-3));
    lit = mix(lit * uWaterShallow, uWaterDeep, k);
    if (uLighting > 0.5) lit = pmcSeaSurface(lit, up, v).rgb;
  }
  if (uLighting > 0.5) {
    // a little aerial perspective far away
    float fog = 1.0 - exp(-length(vRel) / max(uFogDistance, 1.0));
    lit = mix(lit, uSkyColour, 0.35 * fog);
  }
  // the terrain's final colour (linear RGB), before the output transform, seen through the air
  // (atmosphere.ts: off without air and in test modes) at the place's own height over the sphere,
  // the sea's surface over ground below it: between the vertices of a coarse chunk the triangle
  // (a chord) sags kilometres under the sphere when seen from orbit (1.8 km at the middle of a
  // 300 km tile), and the denser air that deep drew the mesh's grid into the haze
  vec3 eye = uAtmoUp * (uAtmoR + uAtmoCamH);
  vec3 place = eye + vRel;
  float surface = (underwater && uWater > 0.5) ? 0.0 : h;
  vec3 seen = normalize(place) * (uDatum + surface) - eye;
  vec3 pmcColour = pmcAerialPerspective(lit, seen);
  gl_FragColor = vec4(pmcColour, 1.0);
  #include <colorspace_fragment>
  #endif
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
uniform vec3 uWaterDeep;
uniform float uFogDistance;
uniform float uLighting;
varying vec3 vNormal;
varying vec3 vRel;
#include <common>
#include <logdepthbuf_pars_fragment>
${SEA_SURFACE}
${ATMOSPHERE_GLSL}
void main() {
  #include <logdepthbuf_fragment>
  vec3 n = normalize(vNormal);
  vec3 v = normalize(-vRel);
  // Drawn only where no terrain is (the stencil): from above, the surface over deep water, as the
  // terrain shader draws it over the sea floor; from below (the camera under the sea), the
  // surface seen through, over the background.
  vec4 sea;
  if (gl_FrontFacing) {
    sea = uLighting > 0.5 ? vec4(pmcSeaSurface(uWaterDeep, n, v).rgb, 1.0) : vec4(uWaterDeep, 1.0);
  } else {
    sea = pmcSeaSurface(vec3(0.0), -n, v);
    sea.rgb = sea.a > 0.0 ? sea.rgb / sea.a : sea.rgb;
  }
  if (uLighting > 0.5) {
    float fog = 1.0 - exp(-length(vRel) / max(uFogDistance, 1.0));
    sea.rgb = mix(sea.rgb, uSkyColour, 0.35 * fog);
  }
  gl_FragColor = vec4(pmcAerialPerspective(sea.rgb, vRel), sea.a);
  #include <colorspace_fragment>
}
`;

export const NOISE_GLSL = NOISE;
