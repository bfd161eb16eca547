// Small PNG measurements for the end-to-end tests (pngjs).

import { PNG } from 'pngjs';

export function decodePng(buffer) {
  return PNG.sync.read(buffer);
}

function pixel(img, x, y) {
  const i = 4 * (y * img.width + x);
  return [img.data[i], img.data[i + 1], img.data[i + 2]];
}

/** The background colour: the most common of the four corner pixels. */
export function backgroundOf(img) {
  const corners = [
    pixel(img, 0, 0),
    pixel(img, img.width - 1, 0),
    pixel(img, 0, img.height - 1),
    pixel(img, img.width - 1, img.height - 1),
  ];
  const key = (c) => c.join(',');
  const counts = new Map();
  for (const c of corners) counts.set(key(c), (counts.get(key(c)) ?? 0) + 1);
  const best = [...counts.entries()].sort((a, b) => b[1] - a[1])[0][0];
  return best.split(',').map(Number);
}

/** Fraction of pixels whose colour differs from `bg` by more than `tolerance` in some channel. */
export function fractionNot(img, bg, tolerance = 12) {
  let n = 0;
  for (let i = 0; i < img.data.length; i += 4) {
    if (
      Math.abs(img.data[i] - bg[0]) > tolerance ||
      Math.abs(img.data[i + 1] - bg[1]) > tolerance ||
      Math.abs(img.data[i + 2] - bg[2]) > tolerance
    ) {
      n++;
    }
  }
  return n / (img.width * img.height);
}

/** Fraction of pixels that differ between two same-sized images by more than `tolerance`. */
export function fractionDifferent(a, b, tolerance = 24) {
  if (a.width !== b.width || a.height !== b.height) return 1;
  let n = 0;
  for (let i = 0; i < a.data.length; i += 4) {
    const d =
      Math.abs(a.data[i] - b.data[i]) +
      Math.abs(a.data[i + 1] - b.data[i + 1]) +
      Math.abs(a.data[i + 2] - b.data[i + 2]);
    if (d > tolerance) n++;
  }
  return n / (a.width * a.height);
}

/** Number of distinct colours (quantised to 5 bits per channel): a crude measure of detail. */
export function colourCount(img) {
  const seen = new Set();
  for (let i = 0; i < img.data.length; i += 4) {
    seen.add(((img.data[i] >> 3) << 10) | ((img.data[i + 1] >> 3) << 5) | (img.data[i + 2] >> 3));
  }
  return seen.size;
}

/** The `w` × `h` window of `img` centred on (cx, cy), clipped to the image. */
export function crop(img, cx, cy, w, h) {
  const x0 = Math.max(0, Math.round(cx - w / 2));
  const y0 = Math.max(0, Math.round(cy - h / 2));
  const x1 = Math.min(img.width, x0 + w);
  const y1 = Math.min(img.height, y0 + h);
  const out = { width: x1 - x0, height: y1 - y0, data: Buffer.alloc(4 * (x1 - x0) * (y1 - y0)) };
  for (let y = y0; y < y1; y++) {
    img.data.copy(out.data, 4 * (y - y0) * out.width, 4 * (y * img.width + x0), 4 * (y * img.width + x1));
  }
  return out;
}
