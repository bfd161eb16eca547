// The servers the steps run against: `pmc serve` (its port read from its first line), a front
// server that serves the fresh viewer/dist in front of an older binary's API, or the mock.

import { spawn } from 'node:child_process';
import { existsSync, readFileSync } from 'node:fs';
import { createServer, request as httpRequest } from 'node:http';
import { extname, join, normalize, sep } from 'node:path';
import { PMC_BIN, USE_MOCK, cleanups, distDir, fetchText, log, run } from './harness.mjs';
import { startMockServer } from './mockServer.mjs';

/**
 * Starts `pmc serve --port 0` with `layout` (null: the default layout) and, when given, `world`
 * (a world file: editing on); reads the port from its "PMC viewer: URL" line. Returns its base URL
 * and a `stop()` (also run at the end).
 */
export async function startPmcServe(layout, { world = null, extra = [], port = 0 } = {}) {
  if (!existsSync(PMC_BIN)) {
    throw new Error(`no pmc binary at ${PMC_BIN}: build it (cargo build --release --bin pmc) or set PMC_BIN`);
  }
  const help = await run(PMC_BIN, ['serve', '--help'], 20_000);
  if (help.code !== 0) {
    throw new Error(
      `${PMC_BIN} has no working \`serve\` command (exit ${help.code}): ${help.out.trim().split('\n')[0]}\n` +
        'Rebuild pmc with the server, or run the tests against the mock with PMC_E2E_MOCK=1.',
    );
  }
  for (const flag of ['--port', '--n-c', '--n-t', ...(world ? ['--world'] : [])]) {
    if (!help.out.includes(flag)) {
      throw new Error(
        `\`pmc serve --help\` does not list ${flag}` +
          (flag === '--world' ? ': this pmc has no editing API; rebuild it (cargo build --release -p pmc-cli)' : ''),
      );
    }
  }
  const args = ['serve', '--port', String(port)];
  if (layout) args.push('--n-c', String(layout.n_c), '--n-t', String(layout.n_t));
  if (world) args.push('--world', world);
  args.push(...extra);
  // PMC_E2E_SERVE_ARGS: more options for every `pmc serve` (e.g. `--cache-mb 16`, to run the
  // steps under a small cache while hunting a stall)
  if (process.env.PMC_E2E_SERVE_ARGS) args.push(...process.env.PMC_E2E_SERVE_ARGS.split(/\s+/).filter(Boolean));
  log(`starting ${PMC_BIN} ${args.join(' ')}`);
  const child = spawn(PMC_BIN, args, { stdio: ['ignore', 'pipe', 'pipe'] });
  let output = '';
  child.stdout.on('data', (d) => (output += d));
  child.stderr.on('data', (d) => (output += d));
  let exited = null;
  child.on('exit', (code, signal) => (exited = { code, signal }));
  const stop = async () => {
    if (exited) return;
    child.kill('SIGTERM');
    const t = setTimeout(() => child.kill('SIGKILL'), 3000);
    await new Promise((r) => (exited ? r() : child.once('exit', r)));
    clearTimeout(t);
    log(`pmc serve stopped${world ? ` (world ${world})` : ''}`);
  };
  cleanups.push(stop);
  const deadline = Date.now() + 60_000;
  let base = null;
  for (;;) {
    if (exited) throw new Error(`pmc serve exited (${JSON.stringify(exited)}):\n${output}`);
    if (!base) {
      const m = /PMC viewer: (http:\/\/\S+)/.exec(output);
      if (m) base = m[1].endsWith('/') ? m[1] : `${m[1]}/`;
    }
    if (base) {
      try {
        const h = await fetchText(`${base}api/v1/health`, 2000);
        if (h.status === 200 && JSON.parse(h.text).ok === true) break;
      } catch {
        // not listening yet
      }
    }
    if (Date.now() > deadline) {
      throw new Error(`pmc serve did not ${base ? 'answer /api/v1/health' : 'print its "PMC viewer: URL" line'} within 60 s:\n${output}`);
    }
    await new Promise((r) => setTimeout(r, 200));
  }
  return { base, stop };
}

const MIME = { '.html': 'text/html; charset=utf-8', '.js': 'text/javascript', '.css': 'text/css', '.png': 'image/png', '.svg': 'image/svg+xml', '.json': 'application/json' };

/**
 * Serves viewer/dist and passes /api/ and /tiles/ (the 3D Tiles mode's tilesets) on to `apiBase`:
 * tests the fresh viewer against the real API.
 */
export async function startFront(apiBase) {
  const api = new URL(apiBase);
  const server = createServer((req, res) => {
    if (req.url.startsWith('/api/') || req.url.startsWith('/tiles/')) {
      const upstream = httpRequest(
        { host: api.hostname, port: api.port, path: req.url, method: req.method, headers: { ...req.headers, host: api.host } },
        (up) => {
          res.writeHead(up.statusCode, up.headers);
          up.pipe(res);
        },
      );
      upstream.on('error', (e) => {
        res.writeHead(502, { 'content-type': 'application/json' });
        res.end(JSON.stringify({ error: `front: ${e.message}` }));
      });
      req.pipe(upstream);
      return;
    }
    let rel = decodeURIComponent(new URL(req.url, 'http://x').pathname);
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
  return { url: `http://127.0.0.1:${server.address().port}/`, stop };
}

/**
 * Starts a server for `layout` (null: the default layout), editing `world` when given. Returns the
 * URL to load the page from (`url`), the server's own (`api`) and `stop()`.
 */
export async function startBackend(layout, { world = null, extra = [] } = {}) {
  const what = layout ? `n_c ${layout.n_c}, n_t ${layout.n_t}` : 'the default layout';
  if (USE_MOCK) {
    if (world) throw new Error('the mock server has no editing API');
    log(`starting the mock server (${what}; planets from ${PMC_BIN} generate)`);
    const mock = await startMockServer({ pmcBin: PMC_BIN, layout: layout ?? { n_c: 8, n_t: 32 }, distDir });
    cleanups.push(() => mock.close());
    return { url: mock.url, api: mock.url, stop: async () => undefined };
  }
  const pmc = await startPmcServe(layout, { world, extra });
  const embedded = await fetchText(pmc.base);
  const fresh = readFileSync(join(distDir, 'index.html'), 'utf8');
  if (embedded.text === fresh || process.env.PMC_E2E_DIRECT === '1') {
    log(`testing the viewer embedded in pmc (${embedded.text === fresh ? 'same build as viewer/dist' : 'PMC_E2E_DIRECT=1'})`);
    return { url: pmc.base, api: pmc.base, stop: pmc.stop, stopApi: pmc.stop };
  }
  log('the viewer embedded in pmc differs from viewer/dist (rebuild pmc to embed it): serving viewer/dist in front of the real API');
  const front = await startFront(pmc.base);
  return {
    url: front.url,
    api: pmc.base,
    /** Stops `pmc serve` alone (the front, if any, stays: a server gone behind a proxy). */
    stopApi: pmc.stop,
    stop: async () => {
      await front.stop();
      await pmc.stop();
    },
  };
}
