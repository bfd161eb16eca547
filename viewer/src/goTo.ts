// Going places: the "go to" box's text read as a place (`LAT, LON[, ALT]`, decimal degrees or
// degrees, minutes and seconds with N/S/E/W), and the flight there: along the great circle, with a
// climb and a descent in between (an arc, not a jump), eased at both ends. Pure: no DOM.

/** A place to go to: degrees, and metres above the datum when given. */
export interface GoToTarget {
  lat: number;
  lon: number;
  alt: number | null;
}

/** The camera along a flight: degrees and metres above the datum. */
export interface FlightPoint {
  lat: number;
  lon: number;
  alt: number;
}

// one angle: -12.5, 12.5S, 27°59'N, 27° 59' 30.5" N, 27d59m (degree, minute and second marks of
// several keyboards)
const ANGLE = /^([+-]?\d+(?:\.\d+)?)\s*(?:[°d]\s*(?:(\d+(?:\.\d+)?)\s*['′m]\s*(?:(\d+(?:\.\d+)?)\s*(?:["″s]|'')\s*)?)?)?\s*([NSEW])?$/i;

function angleOf(text: string): { deg: number; hemisphere: string | null } | null {
  const m = ANGLE.exec(text.trim());
  if (!m) return null;
  const d = Number(m[1]);
  const min = m[2] !== undefined ? Number(m[2]) : 0;
  const sec = m[3] !== undefined ? Number(m[3]) : 0;
  if (min >= 60 || sec >= 60) return null;
  const sign = d < 0 || m[1]!.startsWith('-') ? -1 : 1;
  let deg = sign * (Math.abs(d) + min / 60 + sec / 3600);
  const h = m[4]?.toUpperCase() ?? null;
  if (h !== null) {
    if (sign < 0) return null; // "-12 S" says south twice
    if (h === 'S' || h === 'W') deg = -deg;
  }
  return { deg, hemisphere: h };
}

/** An altitude: metres, or with `m` or `km`. */
function altitudeOf(text: string): number | null {
  const m = /^([+-]?\d+(?:\.\d+)?)\s*(m|km)?$/i.exec(text.trim());
  if (!m) return null;
  return Number(m[1]) * (m[2]?.toLowerCase() === 'km' ? 1000 : 1);
}

/**
 * Reads `LAT, LON[, ALT]` (commas or spaces between them; `27.98, 86.92`, `27°59'N 86°55'E`,
 * `-33.9 18.4 2 km`): the place, or a message saying what is wrong.
 */
export function parseGoTo(text: string): GoToTarget | { error: string } {
  const t = text.trim();
  if (t === '') return { error: 'type a place: latitude, longitude and, if you like, an altitude (27.98, 86.92, 5000)' };
  // with hemispheres, the parts end at N/S and E/W (a DMS angle holds spaces itself); else
  // commas part them, or else spaces
  const hemi = /^(.*?\d\s*['′"″]?\s*[NS])[\s,;]+(.*?\d\s*['′"″]?\s*[EW])(?:[\s,;]+(.+))?$/i.exec(t);
  let parts: string[];
  if (hemi) {
    parts = [hemi[1]!, hemi[2]!, ...(hemi[3] !== undefined ? [hemi[3]] : [])];
  } else {
    parts = t.split(/\s*[,;]\s*/).filter((p) => p !== '');
    if (parts.length === 1) {
      const words = t.split(/\s+/);
      parts = [...words.slice(0, 2), ...(words.length > 2 ? [words.slice(2).join(' ')] : [])];
    }
  }
  if (parts.length < 2 || parts.length > 3) return { error: `"${text}": give a latitude and a longitude, and an altitude if you like` };
  const lat = angleOf(parts[0]!);
  const lon = angleOf(parts[1]!);
  if (lat === null || (lat.hemisphere !== null && !'NS'.includes(lat.hemisphere))) return { error: `"${parts[0]}" is not a latitude` };
  if (lon === null || (lon.hemisphere !== null && !'EW'.includes(lon.hemisphere))) return { error: `"${parts[1]}" is not a longitude` };
  if (Math.abs(lat.deg) > 90) return { error: `latitude ${lat.deg}° is beyond the poles (at most 90°)` };
  if (Math.abs(lon.deg) > 360) return { error: `longitude ${lon.deg}° is more than a turn` };
  let alt: number | null = null;
  if (parts.length === 3) {
    alt = altitudeOf(parts[2]!);
    if (alt === null) return { error: `"${parts[2]}" is not an altitude (metres, or with m or km)` };
  }
  const wrapped = lon.deg >= -180 && lon.deg <= 180 ? lon.deg : ((((lon.deg + 180) % 360) + 360) % 360) - 180;
  return { lat: lat.deg, lon: wrapped, alt };
}

const RAD = Math.PI / 180;

function unit(lat: number, lon: number): [number, number, number] {
  return [Math.cos(lat * RAD) * Math.cos(lon * RAD), Math.cos(lat * RAD) * Math.sin(lon * RAD), Math.sin(lat * RAD)];
}

/** A flight from `from` to `to` over a planet of radius `datum` metres. */
export class Flight {
  /** Seconds it takes. */
  readonly duration: number;
  /** The highest altitude on the way, metres above the datum. */
  readonly peak: number;
  private readonly a: [number, number, number];
  private readonly b: [number, number, number];
  private readonly angle: number;

  constructor(
    private readonly from: FlightPoint,
    private readonly to: FlightPoint,
    datum: number,
  ) {
    if (![from.lat, from.lon, from.alt, to.lat, to.lon, to.alt, datum].every(Number.isFinite) || datum <= 0) {
      throw new Error('a flight needs finite places and a positive radius');
    }
    this.a = unit(from.lat, from.lon);
    this.b = unit(to.lat, to.lon);
    const dot = Math.max(-1, Math.min(1, this.a[0] * this.b[0] + this.a[1] * this.b[1] + this.a[2] * this.b[2]));
    this.angle = Math.acos(dot);
    const ground = this.angle * datum;
    // high enough to see from one end to the other on the way (a third of the way's length,
    // never more than a planet's radius), over the lower end where it lies under the datum (a
    // hop on the sea floor stays on the sea floor)
    const low = Math.max(1, Math.min(from.alt, to.alt));
    const high = Math.max(from.alt, to.alt);
    this.peak = Math.max(high, Math.min(ground / 3, datum) + Math.min(0, from.alt, to.alt));
    // 2 s for a hop, up to 9 s across the planet: longer with every tenfold of the climb and the way
    this.duration = Math.min(9, 2 + 0.9 * Math.log10(1 + ground / 1000) + 0.5 * Math.log10(Math.max(1, this.peak) / low));
  }

  /** The camera at `t` seconds from the start (the end from `duration` on). */
  at(t: number): FlightPoint {
    const u = Math.max(0, Math.min(1, t / this.duration));
    // eased along the way: slow to leave, slow to arrive
    const s = u * u * (3 - 2 * u);
    let p: [number, number, number];
    if (this.angle < 1e-9) {
      p = this.a;
    } else {
      const k = Math.sin(this.angle);
      const wa = Math.sin((1 - s) * this.angle) / k;
      const wb = Math.sin(s * this.angle) / k;
      p = [wa * this.a[0] + wb * this.b[0], wa * this.a[1] + wb * this.b[1], wa * this.a[2] + wb * this.b[2]];
    }
    const lat = Math.asin(Math.max(-1, Math.min(1, p[2]))) / RAD;
    const lon = s >= 1 ? this.to.lon : s <= 0 ? this.from.lon : Math.atan2(p[1], p[0]) / RAD;
    // the altitude in log space (of the height over a floor a metre under both ends and the
    // datum: an end may lie under the sea), from one end to the other with a climb between
    const floor = Math.min(0, this.from.alt, this.to.alt) - 1;
    const la = Math.log(this.from.alt - floor);
    const lb = Math.log(this.to.alt - floor);
    // (the bump brings the middle of the way to the peak: the curve is concave, one top)
    const bump = Math.max(0, Math.log(this.peak - floor) - (la + lb) / 2);
    const alt = u >= 1 ? this.to.alt : u <= 0 ? this.from.alt : floor + Math.exp(la + (lb - la) * s + bump * 4 * s * (1 - s));
    return { lat: u >= 1 ? this.to.lat : lat, lon, alt };
  }
}
