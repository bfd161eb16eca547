// Colour maths shared by the viewer and its end-to-end tests: sRGB transfer functions, CIELAB
// (D65) and the CIE76 colour difference. Self-contained (no imports) so that the end-to-end steps
// load it as it is.

/** An RGB triple. */
export type Rgb = [number, number, number];

/** sRGB component in [0, 1] to linear. */
export function srgbToLinear(c: number): number {
  return c <= 0.04045 ? c / 12.92 : Math.pow((c + 0.055) / 1.055, 2.4);
}

/** Linear component in [0, 1] to sRGB. */
export function linearToSrgb(c: number): number {
  const x = Math.min(1, Math.max(0, c));
  return x <= 0.0031308 ? 12.92 * x : 1.055 * Math.pow(x, 1 / 2.4) - 0.055;
}

/** An 8-bit sRGB colour as linear RGB in [0, 1]. */
export function srgb8ToLinear(c: Rgb): Rgb {
  return [srgbToLinear(c[0] / 255), srgbToLinear(c[1] / 255), srgbToLinear(c[2] / 255)];
}

/** CIELAB (D65 white) of an 8-bit sRGB colour. */
export function srgb8ToLab(c: Rgb): Rgb {
  const [r, g, b] = srgb8ToLinear(c);
  const x = (0.4124564 * r + 0.3575761 * g + 0.1804375 * b) / 0.95047;
  const y = 0.2126729 * r + 0.7151522 * g + 0.072175 * b;
  const z = (0.0193339 * r + 0.119192 * g + 0.9503041 * b) / 1.08883;
  const f = (t: number): number => (t > 216 / 24389 ? Math.cbrt(t) : (24389 / 27 * t + 16) / 116);
  const fx = f(x);
  const fy = f(y);
  const fz = f(z);
  return [116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz)];
}

/** The CIE76 colour difference (Euclidean distance in CIELAB) of two 8-bit sRGB colours. */
export function deltaE76(a: Rgb, b: Rgb): number {
  const p = srgb8ToLab(a);
  const q = srgb8ToLab(b);
  return Math.hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]);
}
