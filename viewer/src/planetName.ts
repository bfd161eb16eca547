// What a planet is called wherever the viewer shows it: the preset and seed, or the elevation
// model's file and the body its radius is (`earth.pmcdem · the Earth`), with the world's file
// first when the server edits one. Pure: no DOM.

import type { PlanetInfo } from './api';

/** Bodies an elevation model's radius names (mean radii, metres), within 1 %. */
const BODIES: readonly { name: string; radius: number }[] = [
  { name: 'the Earth', radius: 6_371_000 },
  { name: 'Mars', radius: 3_389_500 },
  { name: 'the Moon', radius: 1_737_400 },
  { name: 'Venus', radius: 6_051_800 },
  { name: 'Mercury', radius: 2_439_700 },
];

/** The body of radius `r` metres (its name), or its radius in kilometres when none is that size. */
export function bodyOfRadius(r: number): string {
  const body = BODIES.find((b) => Math.abs(r - b.radius) <= 0.01 * b.radius);
  if (body) return body.name;
  return r >= 10_000 ? `radius ${Math.round(r / 1000).toLocaleString('en-US')} km` : `radius ${Math.round(r).toLocaleString('en-US')} m`;
}

/** The planet's name for the panel, the title and the links. */
export function planetName(info: PlanetInfo): string {
  const t = info.terrain;
  let name: string;
  if (info.preset !== null) {
    name = `${info.preset} · seed ${info.seed}`;
  } else if (t && t.kind === 'dem') {
    const datum = info.sea_radius ?? (info.base_radius + info.radius) / 2;
    name = `${t.file ?? t.name} · ${bodyOfRadius(datum)}`;
  } else {
    name = t?.name ?? `seed ${info.seed}`;
  }
  const edit = info.edit;
  return edit && edit.enabled ? `${edit.world} · ${name}` : name;
}

/**
 * What makes a `/planet` answer another planet: everything but the world's edit counts (an edit
 * made meanwhile comes through the edit stream, not as a new planet).
 */
export function planetIdentity(info: PlanetInfo): string {
  const { edit, ...rest } = info;
  return JSON.stringify({ ...rest, edit: edit ? { enabled: edit.enabled } : null });
}
