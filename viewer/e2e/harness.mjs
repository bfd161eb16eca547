// The end-to-end harness: the settings from the environment (see run.mjs), the log, the clean-ups
// run on every exit, timeouts, child processes, and the steps with their results.

import { spawn } from 'node:child_process';
import { existsSync, mkdtempSync, readdirSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
export const viewerDir = resolve(here, '..');
/**
 * The elevation model the steps import: PMC_E2E_DEM, else NOAA's ETOPO5 where Debian's
 * ferret-datasets installs it (scripts/test.sh does), else pmc-dem's one-degree ETOPO60 fixture.
 */
export const DEM_SOURCE = process.env.PMC_E2E_DEM
  ? resolve(process.env.PMC_E2E_DEM)
  : existsSync('/usr/share/ferret-vis/data/etopo5.cdf')
    ? '/usr/share/ferret-vis/data/etopo5.cdf'
    : resolve(viewerDir, '../crates/pmc-dem/tests/fixtures/etopo60.cdf');
export const distDir = join(viewerDir, 'dist');
export const artifacts = join(here, 'artifacts');
// PMC_BIN is relative to the working directory; the default to the repository's target/
export const PMC_BIN = process.env.PMC_BIN ? resolve(process.env.PMC_BIN) : resolve(viewerDir, '../target/release/pmc');
export const CHROMIUM = process.env.CHROMIUM ?? '/usr/bin/chromium';
export const USE_MOCK = process.env.PMC_E2E_MOCK === '1';
export const LAYOUT = { n_c: 4, n_t: 16 };
export const VIEWPORT = { width: 1024, height: 640 };
// How long a view may take to settle: a guard against a hang, not a speed test (the slowest view,
// the Earth descent's 100 m stop, settles in about 15 s on a 2-core machine with software WebGL).
export const READY_MS = 240_000;
/** Whether Mesa's EGL and its software driver (Debian's libegl-mesa0 and libgl1-mesa-dri) are installed. */
function mesaInstalled() {
  const lib = ['/usr/lib', '/usr/lib64'].filter((d) => existsSync(d));
  const dirs = lib.flatMap((d) => [d, ...readdirSync(d).filter((n) => n.endsWith('-linux-gnu')).map((n) => join(d, n))]);
  return dirs.some((d) => existsSync(join(d, 'libEGL_mesa.so.0'))) && dirs.some((d) => existsSync(join(d, 'dri', 'swrast_dri.so')));
}
/**
 * The software renderer behind the steps' WebGL: Mesa's llvmpipe (through ANGLE's EGL back end)
 * where Mesa is installed, as Debian's chromium package brings it, else Chromium's own SwiftShader;
 * PMC_E2E_GL=llvmpipe or swiftshader picks one. A frame costs about a quarter under llvmpipe on
 * two cores (docs/BENCHMARKS.md). The flights' pictures with back faces flagged stay on
 * SwiftShader (`FLIGHTS_GL`); the browser's renderer is logged at launch.
 */
export const GL = process.env.PMC_E2E_GL ?? (mesaInstalled() ? 'llvmpipe' : 'swiftshader');
if (GL !== 'llvmpipe' && GL !== 'swiftshader') throw new Error(`PMC_E2E_GL must be llvmpipe or swiftshader, not ${GL}`);
/**
 * The renderer of the flights (steps 9, 10 and 11), whose pictures with back faces flagged count
 * the pixels where a back face won a single antialiasing sample (a gap narrower than a pixel).
 * Under llvmpipe's multisampling back faces win samples along the far horizon with no gap there
 * (43 to 77 pixels in the view 2 m over the ocean floor, where SwiftShader has 0 to 2, and none
 * under either without multisampling), so the flights keep SwiftShader, whose samples the
 * threshold was measured on.
 */
export const FLIGHTS_GL = 'swiftshader';
/** The headless Chromium of every test with WebGL by `gl`: software, nothing from outside. */
export function chromiumArgs(gl = GL) {
  return [
    '--no-sandbox',
    ...(gl === 'llvmpipe'
      ? ['--use-angle=gl-egl', '--ignore-gpu-blocklist']
      : ['--disable-gpu', '--use-angle=swiftshader', '--enable-unsafe-swiftshader']),
    '--disable-background-networking',
    '--disable-component-update',
    '--disable-sync',
    '--no-first-run',
    '--disable-quic',
  ];
}
// A guard against a hung run, not a speed test: every step takes about 10 minutes on a 2-core
// machine with software WebGL (the viewer draws only when the picture changes), a loaded machine
// longer, and the gallery (PMC_E2E_GALLERY=1) adds its descents with the sky on.
export const TOTAL_MS = 45 * 60_000;

export const started = Date.now();
export const log = (msg) => console.log(`[e2e ${((Date.now() - started) / 1000).toFixed(1)}s] ${msg}`);
/** Run last to first at the end, whatever happens: servers and browsers stopped, files removed. */
export const cleanups = [];
let exiting = false;

export async function cleanup() {
  while (cleanups.length > 0) {
    const fn = cleanups.pop();
    try {
      await fn();
    } catch (e) {
      console.error(`cleanup: ${e?.message ?? e}`);
    }
  }
}

export async function fail(message) {
  if (exiting) return;
  exiting = true;
  console.error(`\nE2E FAILED: ${message}`);
  await cleanup();
  process.exit(1);
}

export function withTimeout(promise, ms, what) {
  let timer;
  return Promise.race([
    promise.finally(() => clearTimeout(timer)),
    new Promise((_, reject) => {
      timer = setTimeout(() => reject(new Error(`${what}: no answer within ${ms / 1000} s`)), ms);
    }),
  ]);
}

export async function fetchText(url, ms = 5000) {
  const res = await withTimeout(fetch(url), ms, `GET ${url}`);
  return { status: res.status, text: await res.text() };
}

export async function run(cmd, args, ms) {
  return withTimeout(
    new Promise((res) => {
      const p = spawn(cmd, args, { stdio: ['ignore', 'pipe', 'pipe'] });
      let out = '';
      p.stdout.on('data', (d) => (out += d));
      p.stderr.on('data', (d) => (out += d));
      p.on('error', (e) => res({ code: -1, out: String(e) }));
      p.on('close', (code) => res({ code, out }));
    }),
    ms,
    `${cmd} ${args.join(' ')}`,
  );
}

// ---- the steps -------------------------------------------------------------------------------

export const results = [];
/** PMC_E2E_ONLY: a comma-separated list of step numbers to run alone, while working on them. */
const ONLY = process.env.PMC_E2E_ONLY ? new Set(process.env.PMC_E2E_ONLY.split(',').map((x) => x.trim())) : null;
/** Whether step 16, the README's gallery, runs (PMC_E2E_GALLERY=1, or PMC_E2E_ONLY naming it). */
export const GALLERY = process.env.PMC_E2E_GALLERY === '1' || (ONLY?.has('16') ?? false);
/** Whether the step named `name` runs (PMC_E2E_ONLY). */
export function selected(name) {
  return !ONLY || ONLY.has(name.split('.')[0]);
}
export async function step(name, fn) {
  if (!selected(name)) return;
  const t0 = Date.now();
  log(`▶ ${name}`);
  try {
    await fn();
    results.push({ name, ok: true, s: (Date.now() - t0) / 1000 });
    log(`✔ ${name} (${((Date.now() - t0) / 1000).toFixed(1)} s)`);
  } catch (e) {
    results.push({ name, ok: false, s: (Date.now() - t0) / 1000, error: short(e) });
    log(`✘ ${name}: ${short(e)}`);
    throw new Error(`${name}: ${short(e)}`);
  }
}

/** An error's message without the browser log Playwright appends to it. */
export function short(e) {
  const m = String(e?.message ?? e);
  const cut = m.search(/\n(Browser logs:|=+ logs =+|Call log:)/);
  return (cut >= 0 ? m.slice(0, cut) : m).slice(0, 2000);
}

export function check(cond, message) {
  if (!cond) throw new Error(message);
}

let sharedDem = null;
/**
 * DEM_SOURCE imported once by `pmc dem import` for the steps that only read it (14, 15, 18 and
 * 19; step 11 checks an import of its own): the `.pmcdem`'s path. A failed import fails each
 * step that asks for it, with the import's output.
 */
export function importedDem() {
  sharedDem ??= (async () => {
    const dir = mkdtempSync(join(tmpdir(), 'pmc-e2e-dem-'));
    cleanups.push(() => rmSync(dir, { recursive: true, force: true }));
    const dem = join(dir, 'earth.pmcdem');
    const imported = await run(PMC_BIN, ['dem', 'import', DEM_SOURCE, '-o', dem, '--quiet'], 300_000);
    if (imported.code !== 0) throw new Error(`pmc dem import ${DEM_SOURCE} failed: ${imported.out}`);
    return dem;
  })();
  return sharedDem;
}
