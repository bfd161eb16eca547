// The viewer's own pure modules (such as src/frames.ts: no imports, no DOM) for the steps, so that
// they compute their views with the viewer's code rather than a copy of it. Node cannot import
// TypeScript (Node 20 has no type stripping): the module is transpiled by Vite's TypeScript
// transform, the one that builds the viewer, and imported from memory.

import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { transformWithOxc } from 'vite';
import { viewerDir } from './harness.mjs';

/** The module `viewer/src/${file}`, which must import nothing. */
export async function viewerModule(file) {
  const path = join(viewerDir, 'src', file);
  const source = readFileSync(path, 'utf8');
  if (/^\s*(import\s|export\s.*\sfrom\s)/m.test(source)) {
    throw new Error(`${path} imports other modules: the steps load only self-contained viewer modules`);
  }
  const { code } = await transformWithOxc(source, path, { lang: 'ts' });
  return import(`data:text/javascript;base64,${Buffer.from(code).toString('base64')}`);
}
