// Imagery for the steps that drape a picture on a planet: a synthetic equirectangular picture and
// a front server that serves viewer/dist, answers `/api/v1/imagery` with that picture and adds
// the `imagery` block to `/api/v1/planet` (docs/specs/http-api-v1.md), passing every other
// `/api/` request on to a `pmc serve`. So the viewer's side of the contract is tested against any
// planet, whether or not the server has imagery of its own.

import { createHash } from 'node:crypto';
import { existsSync, readFileSync } from 'node:fs';
import { createServer, request as httpRequest } from 'node:http';
import { extname, join, normalize, sep } from 'node:path';
import { PNG } from 'pngjs';
import { cleanups, distDir } from './harness.mjs';

/**
 * The synthetic picture's colour (8-bit sRGB) at latitude/longitude (degrees): smooth, periodic
 * in longitude (no edge at the antimeridian), different in every region and far from the
 * preset's own colours, so that a wrong lookup shows.
 */
export function syntheticColour(lat, lon) {
  const a = (lon * Math.PI) / 180;
  const b = (lat * Math.PI) / 180;
  return [
    Math.round(128 + 100 * Math.sin(a)),
    Math.round(128 + 90 * Math.cos(a + 0.6) * Math.cos(b)),
    Math.round(128 + 100 * Math.sin(2 * b + 0.3)),
  ];
}

/** An equirectangular PNG of `width` x `height` cells of `colour(lat, lon)` at the cell centres. */
export function equirectPng(width, height, colour = syntheticColour, extent = [-180, 180, -90, 90]) {
  const png = new PNG({ width, height });
  const [west, east, south, north] = extent;
  for (let y = 0; y < height; y++) {
    const lat = north - ((y + 0.5) * (north - south)) / height;
    for (let x = 0; x < width; x++) {
      const lon = west + ((x + 0.5) * (east - west)) / width;
      const c = colour(lat, lon);
      const i = 4 * (y * width + x);
      png.data[i] = c[0];
      png.data[i + 1] = c[1];
      png.data[i + 2] = c[2];
      png.data[i + 3] = 255;
    }
  }
  return PNG.sync.write(png);
}

/** The picture's colour at (lat, lon) by bilinear interpolation of its cells (decoded `img`). */
export function sampleEquirect(img, extent, lat, lon) {
  const [west, east, south, north] = extent;
  const u = ((((lon - west) % 360) + 360) % 360) / (east - west);
  const v = (north - lat) / (north - south);
  const fx = u * img.width - 0.5;
  const fy = Math.min(img.height - 1, Math.max(0, v * img.height - 0.5));
  const x0 = Math.floor(fx);
  const y0 = Math.floor(fy);
  const tx = fx - x0;
  const ty = fy - y0;
  const wrap = (x) => ((x % img.width) + img.width) % img.width;
  const px = (x, y) => {
    const i = 4 * (Math.min(img.height - 1, y) * img.width + wrap(x));
    return [img.data[i], img.data[i + 1], img.data[i + 2]];
  };
  const a = px(x0, y0);
  const b = px(x0 + 1, y0);
  const c = px(x0, y0 + 1);
  const d = px(x0 + 1, y0 + 1);
  return [0, 1, 2].map((k) => (a[k] * (1 - tx) + b[k] * tx) * (1 - ty) + (c[k] * (1 - tx) + d[k] * tx) * ty);
}

const MIME = { '.html': 'text/html; charset=utf-8', '.js': 'text/javascript', '.css': 'text/css', '.png': 'image/png', '.json': 'application/json' };

/**
 * Serves viewer/dist and the picture `png` (covering `extent`), adds the `imagery` block to
 * `/api/v1/planet` and passes the rest of `/api/` on to `apiBase`. Returns its `url` and `stop()`.
 */
export async function startImageryFront(apiBase, png, extent = [-180, 180, -90, 90]) {
  const api = new URL(apiBase);
  const decoded = PNG.sync.read(png);
  const imagery = {
    url: '/api/v1/imagery',
    extent,
    width: decoded.width,
    height: decoded.height,
    digest: createHash('sha256').update(png).digest('hex'),
  };
  const server = createServer((req, res) => {
    const path = new URL(req.url, 'http://x').pathname;
    if (path === '/api/v1/imagery') {
      res.writeHead(200, { 'content-type': 'image/png', 'content-length': png.length });
      res.end(png);
      return;
    }
    if (path.startsWith('/api/')) {
      const isPlanet = path === '/api/v1/planet' && req.method === 'GET';
      const upstream = httpRequest(
        { host: api.hostname, port: api.port, path: req.url, method: req.method, headers: { ...req.headers, host: api.host, 'accept-encoding': 'identity' } },
        (up) => {
          if (!isPlanet || up.statusCode !== 200) {
            res.writeHead(up.statusCode, up.headers);
            up.pipe(res);
            return;
          }
          const parts = [];
          up.on('data', (d) => parts.push(d));
          up.on('end', () => {
            const body = JSON.stringify({ ...JSON.parse(Buffer.concat(parts).toString('utf8')), imagery });
            res.writeHead(200, { 'content-type': 'application/json' });
            res.end(body);
          });
        },
      );
      upstream.on('error', (e) => {
        res.writeHead(502, { 'content-type': 'application/json' });
        res.end(JSON.stringify({ error: `front: ${e.message}` }));
      });
      req.pipe(upstream);
      return;
    }
    let rel = decodeURIComponent(path);
    if (rel === '/') rel = '/index.html';
    const file = normalize(join(distDir, rel));
    if (!file.startsWith(distDir + sep) || !existsSync(file)) {
      res.writeHead(404, { 'content-type': 'text/plain' });
      res.end('not found');
      return;
    }
    res.writeHead(200, { 'content-type': MIME[extname(file)] ?? 'application/octet-stream' });
    res.end(readFileSync(file));
  });
  await new Promise((r) => server.listen(0, '127.0.0.1', r));
  let closed = false;
  const stop = () =>
    new Promise((r) => {
      if (closed) return r();
      closed = true;
      server.closeAllConnections?.();
      server.close(() => r());
    });
  cleanups.push(stop);
  return { url: `http://127.0.0.1:${server.address().port}/`, stop, imagery };
}
