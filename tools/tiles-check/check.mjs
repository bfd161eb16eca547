#!/usr/bin/env node
// Checks a 3D Tiles 1.1 tileset written by pmc (docs/specs/tiles-v1.md) with the ecosystem's own
// tools: the official 3D Tiles 1.1 JSON schemas (vendored in schema/) and loaders.gl.
//
// Usage: node tools/tiles-check/check.mjs [--max-contents N] DIR_OR_URL
//
//   DIR_OR_URL   a baked folder (holding tileset.json), or the http(s) URL of a tileset.json
//                (`pmc serve`: http://HOST:PORT/tiles/tileset.json)
//   --max-contents N   load at most N tile contents (.glb) with loaders.gl, spread evenly over
//                all of them (default: every one)
//
// 1. Schema: tileset.json and every external tileset reachable from it (the subtree files, whose
//    content URIs end in .json) are validated against tileset.schema.json, every vendored schema
//    registered with Ajv (JSON Schema 2020-12).
// 2. What the schema cannot say: every content URI is relative and resolves (the file exists, or
//    HTTP 200), every tile's geometric error is at most its parent's (across external tilesets too:
//    an external tileset's root against the tile that references it), refine is REPLACE where
//    given and given on every tileset's root, every bounding sphere's radius is not negative, no
//    tileset is reached twice.
// 3. loaders.gl: the root tileset and every external tileset are loaded with Tiles3DLoader
//    (following the content URLs loaders.gl itself resolves, which must be the ones of step 2),
//    and the tile contents too: each must parse to a glTF whose meshes' primitives are triangles
//    with POSITION, at least one triangle in all (tiles-v1.md: every tile in the tree has content,
//    with at least one triangle).
//
// A folder is served over a throwaway HTTP server on 127.0.0.1 for loaders.gl. Every problem is
// printed as `FAIL FILE POINTER: message`; exit status 1 if there is any, else one summary line
// and exit status 0. Exit status 2 for a usage error.

import { readFile, readdir, stat } from 'node:fs/promises';
import http from 'node:http';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import Ajv2020 from 'ajv/dist/2020.js';
import { load } from '@loaders.gl/core';
import { Tiles3DLoader } from '@loaders.gl/3d-tiles';

const HERE = path.dirname(fileURLToPath(import.meta.url));
const SCHEMA_DIR = path.join(HERE, 'schema');
// The vendored schemas' own $id are bare file names ("tile.schema.json") while their $refs are
// relative to their folders ("../common/rootProperty.schema.json"): each is registered under its
// path below this base (an identifier only: nothing is fetched).
const SCHEMA_BASE =
  'https://raw.githubusercontent.com/CesiumGS/3d-tiles/390f7665d4c2a2015d794e218c6af3bbea44f9a6/specification/schema/';
const CONCURRENCY = 8;
const MAX_PRINTED = 50;
const SCHEMA_ERRORS_PER_FILE = 10;

function usage(out = console.error) {
  out('usage: node tools/tiles-check/check.mjs [--max-contents N] DIR_OR_URL');
  out('Validates a 3D Tiles tileset (a baked folder holding tileset.json, or the URL of a');
  out('tileset.json) and every external tileset under it against the 3D Tiles 1.1 schemas, checks');
  out('what the schemas cannot, and loads it all with loaders.gl; exits 1 on any problem.');
}

function parseArgs(argv) {
  let target = null;
  let maxContents = Infinity;
  for (let i = 0; i < argv.length; i++) {
    const a = argv[i];
    if (a === '-h' || a === '--help') {
      usage(console.log);
      process.exit(0);
    } else if (a === '--max-contents' || a.startsWith('--max-contents=')) {
      const v = a.includes('=') ? a.slice(a.indexOf('=') + 1) : argv[++i];
      maxContents = Number(v);
      if (!Number.isInteger(maxContents) || maxContents < 0) {
        console.error(`tiles-check: --max-contents wants a whole number, not ${v}`);
        process.exit(2);
      }
    } else if (a.startsWith('-')) {
      console.error(`tiles-check: unknown option ${a}`);
      usage();
      process.exit(2);
    } else if (target === null) {
      target = a;
    } else {
      console.error('tiles-check: one folder or URL only');
      process.exit(2);
    }
  }
  if (target === null) {
    usage();
    process.exit(2);
  }
  return { target, maxContents };
}

// ---------------------------------------------------------------------------------------------
// Problems

const problems = [];
function fail(file, pointer, message) {
  problems.push(`FAIL ${file}${pointer ? ' ' + pointer : ''}: ${message}`);
}

// ---------------------------------------------------------------------------------------------
// The schemas

async function schemaFiles(dir, rel = '') {
  const out = [];
  for (const e of await readdir(path.join(dir, rel), { withFileTypes: true })) {
    const r = rel ? `${rel}/${e.name}` : e.name;
    if (e.isDirectory()) out.push(...(await schemaFiles(dir, r)));
    else if (e.name.endsWith('.schema.json')) out.push(r);
  }
  return out.sort();
}

async function makeValidator() {
  // Ajv's strict mode, less two of its rules that the official schemas break (and that only
  // police how a schema is written, not what it accepts): strictTypes (`required` and
  // `properties` without `type: "object"` beside them, the type coming from a $ref) and
  // strictRequired (tileset.schema.json's `not: {required: [...]}` naming properties it does not
  // define). Validation itself is unchanged.
  const ajv = new Ajv2020({ strict: true, strictTypes: false, strictRequired: false, allErrors: true });
  // The one format the schemas use (tileset.schemaUri, buffer.uri): an IRI reference, that is
  // anything that resolves as a URL against a base.
  ajv.addFormat('iri-reference', (s) => {
    try {
      new URL(s, 'http://base.invalid/');
      return true;
    } catch {
      return false;
    }
  });
  const files = await schemaFiles(SCHEMA_DIR);
  for (const rel of files) {
    const schema = JSON.parse(await readFile(path.join(SCHEMA_DIR, rel), 'utf8'));
    schema.$id = SCHEMA_BASE + rel;
    ajv.addSchema(schema);
  }
  const validate = ajv.getSchema(SCHEMA_BASE + 'tileset.schema.json');
  if (!validate) throw new Error('tileset.schema.json is missing from the vendored schemas');
  return { validate, count: files.length };
}

// ---------------------------------------------------------------------------------------------
// Where the tileset is: a folder (served on 127.0.0.1 for loaders.gl) or a URL

const MIME = { '.json': 'application/json', '.glb': 'model/gltf-binary' };

async function serveFolder(root) {
  const server = http.createServer(async (req, res) => {
    const rel = decodeURIComponent(new URL(req.url, 'http://localhost').pathname).replace(/^\/+/, '');
    const file = path.resolve(root, rel);
    if (file !== root && !file.startsWith(root + path.sep)) {
      res.writeHead(403).end();
      return;
    }
    try {
      const bytes = await readFile(file);
      res.writeHead(200, { 'Content-Type': MIME[path.extname(file)] ?? 'application/octet-stream' });
      res.end(bytes);
    } catch {
      res.writeHead(404).end();
    }
  });
  await new Promise((resolve, reject) => {
    server.once('error', reject);
    server.listen(0, '127.0.0.1', resolve);
  });
  return server;
}

// A file's name as printed: its path below the folder, or its URL below the tileset's.
function displayName(url, base) {
  return url.startsWith(base) ? decodeURI(url.slice(base.length)) : url;
}

async function fetchBytes(url) {
  const res = await fetch(url);
  if (!res.ok) throw new Error(`HTTP ${res.status}`);
  return new Uint8Array(await res.arrayBuffer());
}

// Runs `fn` over `items`, `CONCURRENCY` at a time.
async function pool(items, fn) {
  let next = 0;
  const worker = async () => {
    while (next < items.length) {
      const i = next++;
      await fn(items[i], i);
    }
  };
  await Promise.all(Array.from({ length: Math.min(CONCURRENCY, items.length) }, worker));
}

// ---------------------------------------------------------------------------------------------
// 1 and 2: the schema and the rest, over every tileset file

async function checkTilesets(ctx) {
  const { validate, base, folder } = ctx;
  const seen = new Set([ctx.rootUrl]);
  const glbs = new Map(); // url -> "file pointer" of its first reference
  glbs.missing = new Set(); // the contents of a folder found missing (not loaded again)
  const jsonUrls = [];
  let valid = 0;
  // Breadth first; each entry: the tileset's URL, the geometric error of the tile that references
  // it (Infinity for the root tileset) and where that reference is.
  let level = [{ url: ctx.rootUrl, parentError: Infinity, from: null }];
  while (level.length > 0) {
    const next = [];
    await pool(level, async ({ url, parentError, from }) => {
      const name = displayName(url, base);
      let doc;
      try {
        const bytes = await fetchBytes(url);
        try {
          doc = JSON.parse(new TextDecoder().decode(bytes));
        } catch (err) {
          throw new Error(`not JSON (${err.message})`);
        }
      } catch (err) {
        if (from) fail(from.file, from.pointer + '/content/uri', `external tileset ${name} cannot be read: ${err.message}`);
        else fail(name, '', `cannot be read: ${err.message}`);
        return;
      }
      if (validate(doc)) {
        valid++;
      } else {
        const errs = validate.errors ?? [];
        for (const e of errs.slice(0, SCHEMA_ERRORS_PER_FILE)) {
          // The parameters the message does not already name.
          const p = e.params ?? {};
          const extra =
            p.additionalProperty !== undefined ? ` '${p.additionalProperty}'`
            : p.allowedValue !== undefined ? ` ${JSON.stringify(p.allowedValue)}`
            : p.allowedValues !== undefined ? ` ${JSON.stringify(p.allowedValues)}`
            : '';
          fail(name, e.instancePath || '/', `${e.message}${extra} (schema ${e.schemaPath})`);
        }
        if (errs.length > SCHEMA_ERRORS_PER_FILE) {
          fail(name, '', `and ${errs.length - SCHEMA_ERRORS_PER_FILE} more schema errors`);
        }
      }
      if (doc === null || typeof doc !== 'object' || typeof doc.root !== 'object' || doc.root === null) return;
      if (doc.asset && doc.asset.version !== '1.1' && doc.asset.version !== '1.0') {
        fail(name, '/asset/version', `3D Tiles version ${JSON.stringify(doc.asset.version)}, not 1.0 or 1.1`);
      }
      if (doc.root.refine === undefined) {
        fail(name, '/root', 'the root tile of a tileset must have refine (3D Tiles 1.1, tile.refine)');
      }
      if (from && doc.root.geometricError >= 0 && !(doc.root.geometricError <= parentError)) {
        fail(name, '/root/geometricError',
          `${doc.root.geometricError} above ${parentError}, the error of the tile that references this tileset (${from.file} ${from.pointer})`);
      }
      // The tiles, depth first.
      const stack = [{ tile: doc.root, pointer: '/root', parentError: Infinity }];
      while (stack.length > 0) {
        const { tile, pointer, parentError: pe } = stack.pop();
        if (tile === null || typeof tile !== 'object') continue;
        const ge = tile.geometricError;
        const geOk = typeof ge === 'number' && Number.isFinite(ge) && ge >= 0;
        if (!geOk) {
          fail(name, pointer + '/geometricError', `must be a number >= 0, is ${JSON.stringify(ge)}`);
        } else if (!(ge <= pe)) {
          fail(name, pointer + '/geometricError', `${ge} above its parent's ${pe}`);
        }
        if (tile.refine !== undefined && tile.refine !== 'REPLACE') {
          fail(name, pointer + '/refine', `${JSON.stringify(tile.refine)}, pmc writes REPLACE`);
        }
        const bv = tile.boundingVolume;
        if (bv === null || typeof bv !== 'object' || Object.keys(bv).length === 0) {
          fail(name, pointer + '/boundingVolume', 'missing');
        } else if (Array.isArray(bv.sphere) && bv.sphere.length === 4 && !(bv.sphere[3] >= 0)) {
          fail(name, pointer + '/boundingVolume/sphere/3', `radius ${bv.sphere[3]}: must not be negative`);
        }
        const contents = tile.content ? [[tile.content, pointer + '/content']] : [];
        if (Array.isArray(tile.contents)) tile.contents.forEach((c, i) => contents.push([c, `${pointer}/contents/${i}`]));
        for (const [content, cp] of contents) {
          const uri = content?.uri;
          if (typeof uri !== 'string') continue; // the schema has said so
          if (/^[a-z][a-z0-9+.-]*:/i.test(uri) || uri.startsWith('/')) {
            fail(name, cp + '/uri', `${uri} is not relative (tiles-v1.md: URLs inside the files are relative)`);
          }
          if (folder) {
            // Within the folder (an HTTP server would quietly drop `..` above its root).
            const rel = path.posix.normalize(path.posix.join(path.posix.dirname(name), uri.split(/[?#]/)[0]));
            if (rel.startsWith('../') || rel === '..') {
              fail(name, cp + '/uri', `${uri} points outside the folder`);
              continue;
            }
          }
          const target = new URL(uri, url).href;
          const ref = { file: name, pointer };
          const ext = new URL(target).pathname.split('.').pop().toLowerCase();
          if (ext === 'json') {
            if (seen.has(target)) {
              fail(name, cp + '/uri', `${displayName(target, base)} is referenced twice (or a cycle)`);
              continue;
            }
            seen.add(target);
            next.push({ url: target, parentError: geOk ? ge : pe, from: ref });
          } else if (ext === 'glb') {
            if (!glbs.has(target)) glbs.set(target, ref);
          } else {
            fail(name, cp + '/uri', `${uri}: pmc writes only .json (external tilesets) and .glb contents`);
          }
        }
        if (Array.isArray(tile.children)) {
          tile.children.forEach((c, i) =>
            stack.push({ tile: c, pointer: `${pointer}/children/${i}`, parentError: geOk ? ge : pe }),
          );
        }
      }
      jsonUrls.push(url);
    });
    level = next;
  }
  // The contents of a folder exist (a URL's are fetched when loaded, below).
  if (folder) {
    await pool([...glbs], async ([url, ref]) => {
      const rel = displayName(url, base);
      try {
        const s = await stat(path.join(folder, rel));
        if (!s.isFile()) throw new Error('not a file');
      } catch {
        fail(ref.file, ref.pointer + '/content/uri', `content ${rel} does not exist`);
        glbs.missing.add(url);
      }
    });
  }
  return { valid, jsonUrls, glbs };
}

// ---------------------------------------------------------------------------------------------
// 3: loaders.gl

// Problems of a parsed content (Tiles3DLoader's result for a glb: `{type: 'glTF', gltf}`).
function contentProblems(content) {
  if (content?.type !== 'glTF' || !content.gltf) return [`parsed to ${content?.type ?? 'nothing'}, not glTF`];
  const g = content.gltf;
  const out = [];
  let triangles = 0;
  (g.meshes ?? []).forEach((mesh, m) => {
    (mesh.primitives ?? []).forEach((p, i) => {
      const at = `/meshes/${m}/primitives/${i}`;
      const pos = p.attributes?.POSITION;
      const vertices = pos?.count ?? (pos?.value ? pos.value.length / 3 : 0);
      if (!pos || !(vertices > 0)) out.push(`${at}: no POSITION`);
      if (p.mode !== undefined && p.mode !== 4) out.push(`${at}: mode ${p.mode}, not triangles`);
      const n = p.indices ? (p.indices.count ?? p.indices.value?.length ?? 0) : vertices;
      if (n % 3 !== 0) out.push(`${at}: ${n} indices, not a whole number of triangles`);
      triangles += Math.floor(n / 3);
    });
  });
  if (triangles === 0) out.push('no triangle (tiles-v1.md: every tile in the tree has content, with at least one triangle)');
  return out;
}

async function loadWithLoadersGl(ctx, expected, maxContents) {
  const { base, rootUrl } = ctx;
  const tilesetUrls = [];
  const contentUrls = new Set();
  const seen = new Set([rootUrl]); // a cycle was reported above; here it is only cut
  let level = [rootUrl];
  while (level.length > 0) {
    const next = [];
    await pool(level, async (url) => {
      let ts;
      try {
        ts = await load(url, Tiles3DLoader);
      } catch (err) {
        fail(displayName(url, base), '', `loaders.gl could not load it: ${err.message}`);
        return;
      }
      if (ts?.type !== 'TILES3D' || !ts.root) {
        fail(displayName(url, base), '', `loaders.gl did not read it as a 3D Tiles tileset (type ${ts?.type})`);
        return;
      }
      tilesetUrls.push(url);
      const stack = [ts.root];
      while (stack.length > 0) {
        const t = stack.pop();
        if (t.contentUrl) {
          if (t.type === 'json') {
            if (!seen.has(t.contentUrl)) next.push(t.contentUrl);
            seen.add(t.contentUrl);
          }
          else if (t.type === 'scenegraph') contentUrls.add(t.contentUrl);
          else fail(displayName(url, base), '', `loaders.gl reads content ${t.contentUrl} as ${t.type}`);
        }
        stack.push(...(t.children ?? []));
      }
    });
    level = next;
  }
  // loaders.gl must have found what step 2 found.
  const ours = new Set(expected.jsonUrls);
  const theirs = new Set(tilesetUrls);
  for (const u of ours) if (!theirs.has(u)) fail(displayName(u, base), '', 'not reached by loaders.gl');
  for (const u of theirs) if (!ours.has(u)) fail(displayName(u, base), '', 'reached by loaders.gl only');
  for (const u of expected.glbs.keys()) if (!contentUrls.has(u)) fail(displayName(u, base), '', 'content not reached by loaders.gl');
  for (const u of contentUrls) if (!expected.glbs.has(u)) fail(displayName(u, base), '', 'content reached by loaders.gl only');

  // The contents: all, or `maxContents` spread evenly.
  const all = [...contentUrls].sort();
  let chosen = all;
  if (all.length > maxContents) {
    chosen = [];
    for (let i = 0; i < maxContents; i++) chosen.push(all[Math.floor((i * all.length) / maxContents)]);
  }
  let loaded = 0;
  const toLoad = chosen.filter((url) => !expected.glbs.missing.has(url));
  await pool(toLoad, async (url) => {
    const name = displayName(url, base);
    const ref = expected.glbs.get(url);
    let content;
    try {
      content = await load(url, Tiles3DLoader);
    } catch (err) {
      const where = ref ? ` (the content of ${ref.file} ${ref.pointer})` : '';
      fail(name, '', `loaders.gl could not load it${where}: ${err.message}`);
      return;
    }
    const bad = contentProblems(content);
    for (const b of bad) fail(name, '', b);
    if (bad.length === 0) loaded++;
  });
  return { tilesets: tilesetUrls.length, contents: loaded, chosen: chosen.length, total: all.length };
}

// ---------------------------------------------------------------------------------------------

async function main() {
  const { target, maxContents } = parseArgs(process.argv.slice(2));
  const { validate } = await makeValidator();
  let server = null;
  const ctx = { validate, folder: null, base: '', rootUrl: '' };
  if (/^https?:\/\//i.test(target)) {
    ctx.rootUrl = new URL(target).href;
    ctx.base = new URL('.', ctx.rootUrl).href;
  } else {
    ctx.folder = path.resolve(target);
    try {
      await stat(path.join(ctx.folder, 'tileset.json'));
    } catch {
      console.error(`tiles-check: ${target} holds no tileset.json`);
      process.exit(1);
    }
    server = await serveFolder(ctx.folder);
    ctx.base = `http://127.0.0.1:${server.address().port}/`;
    ctx.rootUrl = ctx.base + 'tileset.json';
  }
  try {
    const tilesets = await checkTilesets(ctx);
    const loaded = await loadWithLoadersGl(ctx, tilesets, maxContents);
    if (problems.length > 0) {
      for (const p of problems.slice(0, MAX_PRINTED)) console.log(p);
      if (problems.length > MAX_PRINTED) console.log(`... and ${problems.length - MAX_PRINTED} more`);
      const n = problems.length;
      console.log(`3D Tiles check: FAILED, ${n} problem${n === 1 ? '' : 's'} in ${target}`);
      process.exitCode = 1;
      return;
    }
    const contents =
      loaded.chosen < loaded.total
        ? `${loaded.contents} of ${loaded.total} contents (--max-contents ${maxContents})`
        : `${loaded.contents} contents`;
    console.log(
      `3D Tiles check: ${tilesets.valid} tileset files valid against the 3D Tiles 1.1 schemas; ` +
        `loaders.gl loaded ${loaded.tilesets} tilesets and ${contents}`,
    );
  } finally {
    server?.close();
  }
}

main().catch((err) => {
  console.error(`tiles-check: ${err.stack ?? err}`);
  process.exit(1);
});
