#!/usr/bin/env node
// Validates GLB (or glTF) files with the Khronos glTF validator.
//
// Usage: node tools/gltf-validate/validate.mjs FILE.glb [MORE.glb ...]
//
// Prints one summary line per file (errors, warnings, infos, hints and the first few messages with
// their codes and JSON pointers), then exits 1 if any file has errors or could not be read or
// validated at all. Warnings, infos and hints do not fail the run.
//
// Environment: GLTF_VALIDATE_MAX_MESSAGES (default 5) sets how many messages are printed per file.

import { readFile } from 'node:fs/promises';
import path from 'node:path';
import * as validator from 'gltf-validator';

const SEVERITY = ['error', 'warning', 'info', 'hint'];
const maxMessages = Number.parseInt(process.env.GLTF_VALIDATE_MAX_MESSAGES ?? '5', 10) || 5;

function usage() {
  console.error('usage: node tools/gltf-validate/validate.mjs FILE.glb [MORE.glb ...]');
  console.error('Validates each file with the Khronos glTF validator ' + validator.version() + ';');
  console.error('exits 1 if any file has errors (warnings are allowed).');
}

async function validateFile(file) {
  let bytes;
  try {
    bytes = new Uint8Array(await readFile(file));
  } catch (err) {
    console.log(`${file}: FAIL cannot read file: ${err.message}`);
    return false;
  }
  let report;
  try {
    report = await validator.validateBytes(bytes, {
      uri: path.basename(file),
      maxIssues: 0,
      writeTimestamp: false,
      // GLB files are self-contained; report any external reference as unresolved.
      externalResourceFunction: (uri) => Promise.reject(`external resource not available: ${uri}`),
    });
  } catch (err) {
    console.log(`${file}: FAIL validator could not read the asset: ${err}`);
    return false;
  }
  const issues = report.issues ?? {};
  const errors = issues.numErrors ?? 0;
  const warnings = issues.numWarnings ?? 0;
  const infos = issues.numInfos ?? 0;
  const hints = issues.numHints ?? 0;
  const messages = (issues.messages ?? [])
    .slice()
    .sort((a, b) => a.severity - b.severity)
    .slice(0, maxMessages)
    .map((m) => {
      const where = m.pointer ?? (m.offset !== undefined ? `@${m.offset}` : '');
      return `[${SEVERITY[m.severity] ?? m.severity}] ${m.code}${where ? ' ' + where : ''}: ${m.message}`;
    });
  const status = errors > 0 ? 'FAIL' : 'ok';
  const counts = `${errors} errors, ${warnings} warnings, ${infos} infos, ${hints} hints`;
  const more = messages.length ? ' | ' + messages.join(' | ') : '';
  console.log(`${file}: ${status} ${counts}${more}`);
  return errors === 0;
}

const files = process.argv.slice(2);
if (files.length === 0 || files.includes('-h') || files.includes('--help')) {
  usage();
  process.exit(files.length === 0 ? 2 : 0);
}

let allOk = true;
for (const file of files) {
  allOk = (await validateFile(file)) && allOk;
}
process.exit(allOk ? 0 : 1);
