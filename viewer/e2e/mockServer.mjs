// A stand-in for `pmc serve`, for developing the viewer without the Rust server: it serves
// viewer/dist and answers the HTTP API v1 (docs/specs/http-api-v1.md) from planets exported by
// `pmc generate ... -o planet.glb` (one GLB node per chunk, with every vertex attribute), re-encoded
// as chunk-mesh-v1. Bounding spheres come from the vertices, so they are tighter than the real
// server's; chunks without triangles are missing from the list.
//
//   node e2e/mockServer.mjs [--port 8080] [--n-c 4] [--n-t 16]      (PMC_BIN picks the binary)

import { execFile } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { createServer } from 'node:http';
import { tmpdir } from 'node:os';
import { extname, join, normalize, resolve, sep } from 'node:path';
import { fileURLToPath } from 'node:url';
import { promisify } from 'node:util';

const run = promisify(execFile);
const here = fileURLToPath(new URL('.', import.meta.url));

const PRESETS = [
  { name: 'sphere', description: 'an exact sphere, for checks' },
  { name: 'earthlike', description: 'continents, seas, mountains, caves and overhangs' },
  { name: 'moon', description: 'craters, maria, lava tubes' },
  { name: 'mars', description: 'canyons, volcanoes, polar caps, caves' },
];
const PALETTES = {
  sphere: { a: [0.7, 0.7, 0.7], b: [0.5, 0.5, 0.55] },
  earthlike: { a: [0.8, 0.7, 0.5], b: [0.3, 0.5, 0.2] },
  moon: { a: [0.55, 0.55, 0.55], b: [0.35, 0.35, 0.37] },
  mars: { a: [0.7, 0.35, 0.2], b: [0.45, 0.25, 0.15] },
};
const FACES = ['top', 'bottom', 'north', 'south', 'east', 'west'];
const FACE_FRAMES = [
  { normal: [0, 1, 0], u: [-1, 0, 0], v: [0, 0, 1] },
  { normal: [0, -1, 0], u: [-1, 0, 0], v: [0, 0, -1] },
  { normal: [0, 0, -1], u: [-1, 0, 0], v: [0, 1, 0] },
  { normal: [0, 0, 1], u: [-1, 0, 0], v: [0, -1, 0] },
  { normal: [1, 0, 0], u: [0, 0, -1], v: [0, 1, 0] },
  { normal: [-1, 0, 0], u: [0, 0, 1], v: [0, 1, 0] },
];
const TYPES = { 5120: Int8Array, 5121: Uint8Array, 5122: Int16Array, 5123: Uint16Array, 5125: Uint32Array, 5126: Float32Array };
const SIZES = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4 };

function parseGlb(buf) {
  const dv = new DataView(buf.buffer, buf.byteOffset, buf.byteLength);
  if (dv.getUint32(0, true) !== 0x46546c67) throw new Error('not a GLB');
  const jsonLen = dv.getUint32(12, true);
  const json = JSON.parse(buf.subarray(20, 20 + jsonLen).toString('utf8'));
  const binStart = 20 + jsonLen + 8;
  const binLen = 20 + jsonLen < buf.byteLength ? dv.getUint32(20 + jsonLen, true) : 0;
  const bin = new Uint8Array(binLen);
  bin.set(buf.subarray(binStart, binStart + binLen));
  const accessor = (index) => {
    const a = json.accessors[index];
    const view = json.bufferViews[a.bufferView];
    const T = TYPES[a.componentType];
    const n = a.count * SIZES[a.type];
    return new T(bin.buffer, (view.byteOffset ?? 0) + (a.byteOffset ?? 0), n);
  };
  return { json, accessor };
}

const pad4 = (n) => (n + 3) & ~3;

function encodeChunk(face, level, i, j, k, origin, attrs) {
  const { positions, normals, colors, heights, water, materials, indices } = attrs;
  const V = positions.length / 3;
  const I = indices.length;
  const u32 = V > 65536;
  const size = 56 + 12 * V + pad4(3 * V) + 4 * V + 4 * V + 4 * V + pad4(V) + pad4((u32 ? 4 : 2) * I);
  const out = new Uint8Array(size);
  const dv = new DataView(out.buffer);
  out.set([0x50, 0x4d, 0x43, 0x4d]);
  dv.setUint16(4, 1, true);
  dv.setUint16(6, u32 ? 1 : 0, true);
  dv.setUint8(8, face);
  dv.setUint8(9, level);
  dv.setUint32(12, i, true);
  dv.setUint32(16, j, true);
  dv.setUint32(20, k, true);
  origin.forEach((x, n) => dv.setFloat64(24 + 8 * n, x, true));
  dv.setUint32(48, V, true);
  dv.setUint32(52, I, true);
  let at = 56;
  new Float32Array(out.buffer, at, 3 * V).set(positions);
  at += 12 * V;
  for (let n = 0; n < 3 * V; n++) dv.setInt8(at + n, Math.round(Math.max(-1, Math.min(1, normals[n])) * 127));
  at += pad4(3 * V);
  out.set(colors, at);
  at += 4 * V;
  new Float32Array(out.buffer, at, V).set(heights);
  at += 4 * V;
  new Float32Array(out.buffer, at, V).set(water);
  at += 4 * V;
  for (let n = 0; n < V; n++) out[at + n] = materials[n];
  at += pad4(V);
  if (u32) new Uint32Array(out.buffer, at, I).set(indices);
  else new Uint16Array(out.buffer, at, I).set(indices);
  return out;
}

async function buildPlanet(pmcBin, preset, seed, layout, work) {
  const file = join(work, `${preset}-${seed}.glb`);
  await run(pmcBin, [
    'generate', '--preset', preset, '--seed', seed, '--n-c', String(layout.n_c), '--n-t', String(layout.n_t),
    '--d-b', String(layout.d_b), '--l-d', String(layout.l_d), '--d-c', String(layout.d_c), '-q', '-o', file,
  ]);
  const { json, accessor } = parseGlb(readFileSync(file));
  const extras = json.asset.extras;
  const chunks = new Map();
  let rMin = Infinity;
  let rMax = 0;
  for (const node of json.nodes) {
    const m = /^(\w+)\/L(\d+)\/(\d+)_(\d+)_(\d+)$/.exec(node.name ?? '');
    if (!m || node.mesh === undefined) continue;
    const [, faceName, level, i, j, k] = m;
    const prim = json.meshes[node.mesh].primitives[0];
    const origin = node.translation ?? [0, 0, 0];
    const positions = accessor(prim.attributes.POSITION);
    const lo = [Infinity, Infinity, Infinity];
    const hi = [-Infinity, -Infinity, -Infinity];
    for (let n = 0; n < positions.length; n += 3) {
      let r2 = 0;
      for (let c = 0; c < 3; c++) {
        const w = origin[c] + positions[n + c];
        lo[c] = Math.min(lo[c], w);
        hi[c] = Math.max(hi[c], w);
        r2 += w * w;
      }
      rMin = Math.min(rMin, Math.sqrt(r2));
      rMax = Math.max(rMax, Math.sqrt(r2));
    }
    const center = lo.map((x, c) => (x + hi[c]) / 2);
    const radius = Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) / 2 + 0.01;
    const key = `${faceName}/${level}/${i}/${j}/${k}`;
    const bytes = encodeChunk(FACES.indexOf(faceName), +level, +i, +j, +k, origin, {
      positions,
      normals: accessor(prim.attributes.NORMAL),
      colors: accessor(prim.attributes.COLOR_0),
      heights: accessor(prim.attributes._HEIGHT),
      water: accessor(prim.attributes._WATER_DEPTH),
      materials: accessor(prim.attributes._MATERIAL),
      indices: accessor(prim.indices),
    });
    chunks.set(key, { key, face: faceName, level: +level, i: +i, j: +j, k: +k, center, radius, bytes });
  }
  const radius = extras.radius;
  return {
    info: {
      format: 'pmc-planet',
      version: 1,
      preset,
      seed,
      presets: PRESETS,
      layout,
      radius,
      base_radius: layout.d_b,
      sea_radius: extras.sea_radius,
      surface_bounds: [rMin, rMax],
      chunk_count: 6 * layout.n_c * layout.n_c * layout.d_c,
      face_tiles: layout.n_c * layout.n_t,
      depth_tiles: layout.n_t * layout.d_c,
      faces: FACES.map((name, index) => ({ name, index, ...FACE_FRAMES[index] })),
      materials: extras.materials,
      palette: PALETTES[preset] ?? PALETTES.sphere,
    },
    chunks,
  };
}

const MIME = { '.html': 'text/html; charset=utf-8', '.js': 'text/javascript', '.css': 'text/css', '.json': 'application/json', '.png': 'image/png', '.svg': 'image/svg+xml' };

/**
 * Starts the mock. Returns `{ url, port, close() }`.
 * @param {{ pmcBin: string, port?: number, layout?: object, distDir?: string, defaultPreset?: string, defaultSeed?: string, delayMs?: number }} opts
 */
export async function startMockServer(opts) {
  const layout = { n_c: 4, n_t: 16, d_b: 1744, l_d: 4, d_c: 2, ...opts.layout };
  const distDir = resolve(opts.distDir ?? join(here, '..', 'dist'));
  const work = mkdtempSync(join(tmpdir(), 'pmc-mock-'));
  const planets = new Map();
  const stats = { generated: 0 };
  const planet = (preset, seed) => {
    const id = `${preset}/${seed}`;
    if (!planets.has(id)) planets.set(id, buildPlanet(opts.pmcBin, preset, seed, layout, work));
    return planets.get(id);
  };
  const json = (res, status, body) => {
    res.writeHead(status, { 'content-type': 'application/json', 'cache-control': 'no-store' });
    res.end(JSON.stringify(body));
  };
  const server = createServer(async (req, res) => {
    try {
      const url = new URL(req.url, 'http://x');
      const q = url.searchParams;
      if (url.pathname.startsWith('/api/')) {
        const preset = q.get('preset') ?? opts.defaultPreset ?? 'earthlike';
        const seed = q.get('seed') ?? opts.defaultSeed ?? '7';
        if (!PRESETS.some((p) => p.name === preset)) return json(res, 400, { error: `unknown preset "${preset}"` });
        if (!/^\d+$/.test(seed)) return json(res, 400, { error: `seed must be a decimal u64, not "${seed}"` });
        const path = url.pathname;
        if (path === '/api/v1/health') return json(res, 200, { ok: true, version: 'mock' });
        if (path === '/api/v1/stats') return json(res, 200, { planets: planets.size, ...stats });
        const p = await planet(preset, seed);
        if (path === '/api/v1/planet') return json(res, 200, p.info);
        if (path === '/api/v1/chunks') {
          const at = ['x', 'y', 'z'].map((k) => Number(q.get(k)));
          const range = Number(q.get('range'));
          const limit = Math.min(4096, Number(q.get('limit') ?? 512));
          if (![...at, range].every(Number.isFinite) || !(range > 0)) return json(res, 400, { error: 'x, y, z and range > 0 are required' });
          const list = [];
          for (const c of p.chunks.values()) {
            const distance = Math.max(0, Math.hypot(c.center[0] - at[0], c.center[1] - at[1], c.center[2] - at[2]) - c.radius);
            if (distance <= range) list.push({ key: c.key, face: c.face, level: c.level, i: c.i, j: c.j, k: c.k, center: c.center, radius: c.radius, distance });
          }
          list.sort((a, b) => a.distance - b.distance);
          return json(res, 200, { chunks: list.slice(0, limit), total_in_range: list.length });
        }
        const m = /^\/api\/v1\/chunk\/(\w+\/\d+\/\d+\/\d+\/\d+)$/.exec(path);
        if (m) {
          const c = p.chunks.get(m[1]);
          if (!c) return json(res, 404, { error: `no chunk ${m[1]} with surface in this layout (mock)` });
          if (opts.delayMs) await new Promise((r) => setTimeout(r, opts.delayMs));
          stats.generated++;
          res.writeHead(200, { 'content-type': 'application/octet-stream', 'content-length': c.bytes.byteLength });
          return res.end(Buffer.from(c.bytes.buffer, c.bytes.byteOffset, c.bytes.byteLength));
        }
        return json(res, 404, { error: `no API endpoint ${path}` });
      }
      let rel = decodeURIComponent(url.pathname);
      if (rel === '/' || rel === '') rel = '/index.html';
      const file = normalize(join(distDir, rel));
      if (!file.startsWith(distDir + sep)) return json(res, 403, { error: 'forbidden' });
      let body;
      try {
        body = readFileSync(file);
      } catch {
        res.writeHead(404, { 'content-type': 'text/plain' });
        return res.end('not found');
      }
      res.writeHead(200, { 'content-type': MIME[extname(file)] ?? 'application/octet-stream' });
      res.end(body);
    } catch (e) {
      json(res, 500, { error: String(e?.message ?? e) });
    }
  });
  await new Promise((r) => server.listen(opts.port ?? 0, '127.0.0.1', r));
  const port = server.address().port;
  return {
    port,
    url: `http://127.0.0.1:${port}/`,
    close: () =>
      new Promise((r) => {
        server.closeAllConnections?.();
        server.close(() => r());
        rmSync(work, { recursive: true, force: true });
      }),
  };
}

if (process.argv[1] && resolve(process.argv[1]) === fileURLToPath(import.meta.url)) {
  const arg = (name, def) => {
    const i = process.argv.indexOf(name);
    return i >= 0 ? process.argv[i + 1] : def;
  };
  const pmcBin = process.env.PMC_BIN ?? resolve(here, '..', '..', 'target', 'release', 'pmc');
  const s = await startMockServer({
    pmcBin,
    port: Number(arg('--port', '8080')),
    layout: { n_c: Number(arg('--n-c', '4')), n_t: Number(arg('--n-t', '16')) },
  });
  console.log(`mock PMC server on ${s.url}`);
}
