// Typed client for the PMC HTTP API, version 1 (docs/specs/http-api-v1.md).

import { decodeChunk, type DecodedChunk } from './chunkDecode';

export type Vec3Tuple = [number, number, number];

export interface PresetInfo {
  name: string;
  description: string;
}

export interface Layout {
  n_c: number;
  n_t: number;
  d_b: number;
  l_d: number;
  d_c: number;
}

export interface FaceInfo {
  name: string;
  index: number;
  normal: Vec3Tuple;
  u: Vec3Tuple;
  v: Vec3Tuple;
}

export interface PlanetInfo {
  format: string;
  version: number;
  preset: string;
  /** A decimal u64, kept as a string. */
  seed: string;
  presets: PresetInfo[];
  layout: Layout;
  radius: number;
  base_radius: number;
  sea_radius: number | null;
  surface_bounds: [number, number] | null;
  chunk_count: number;
  face_tiles: number;
  depth_tiles: number;
  /** Highest level of detail of the layout (absent from older servers). */
  max_level?: number;
  faces: FaceInfo[];
  materials: string[];
  palette: { a: Vec3Tuple; b: Vec3Tuple };
}

export interface ChunkEntry {
  key: string;
  face: string;
  level: number;
  i: number;
  j: number;
  k: number;
  center: Vec3Tuple;
  radius: number;
  distance: number;
}

export interface ChunkList {
  chunks: ChunkEntry[];
  total_in_range: number;
}

export interface PlanetChoice {
  preset?: string | undefined;
  seed?: string | undefined;
}

/** An error from the API: the HTTP status (0 for a network failure) and the server's message. */
export class ApiError extends Error {
  constructor(
    message: string,
    readonly status: number,
    readonly url: string,
    /** Seconds from a `Retry-After` header (503), when given. */
    readonly retryAfter: number | null = null,
  ) {
    super(message);
    this.name = 'ApiError';
  }
  /** True when retrying later may succeed (busy server, network trouble). */
  get transient(): boolean {
    return this.status === 0 || this.status === 503 || this.status === 502 || this.status === 504;
  }
}

/** Whether an error is the result of an `AbortSignal`. */
export function isAbort(e: unknown): boolean {
  return (
    (e instanceof DOMException && e.name === 'AbortError') ||
    (e instanceof Error && e.name === 'AbortError')
  );
}

export type FetchFn = (input: string, init?: RequestInit) => Promise<Response>;

export class PmcApi {
  private readonly fetchFn: FetchFn;

  constructor(
    /** Prefix of the API, e.g. `api/v1` (relative to the page) or `http://host:8080/api/v1`. */
    readonly base = 'api/v1',
    fetchFn?: FetchFn,
  ) {
    this.fetchFn = fetchFn ?? ((input, init) => fetch(input, init));
  }

  /** The URL of `path` with the planet choice and extra parameters as query string. */
  url(path: string, planet: PlanetChoice = {}, params: Record<string, string | number> = {}): string {
    const q = new URLSearchParams();
    if (planet.preset) q.set('preset', planet.preset);
    if (planet.seed !== undefined && planet.seed !== '') q.set('seed', planet.seed);
    for (const [k, v] of Object.entries(params)) q.set(k, String(v));
    const qs = q.toString();
    return `${this.base}/${path}${qs ? `?${qs}` : ''}`;
  }

  private async request(url: string, signal?: AbortSignal): Promise<Response> {
    let res: Response;
    try {
      res = await this.fetchFn(url, signal ? { signal } : {});
    } catch (e) {
      if (isAbort(e)) throw e;
      throw new ApiError(`cannot reach the PMC server (${String(e)})`, 0, url);
    }
    if (!res.ok) {
      let message = `${res.status} ${res.statusText}`.trim();
      try {
        const body: unknown = await res.json();
        if (body && typeof body === 'object' && 'error' in body) {
          message = `${message}: ${String((body as { error: unknown }).error)}`;
        }
      } catch {
        // not JSON: keep the status line
      }
      const ra = res.headers.get('Retry-After');
      const retryAfter = ra !== null && Number.isFinite(Number(ra)) ? Number(ra) : null;
      throw new ApiError(message, res.status, url, retryAfter);
    }
    return res;
  }

  private async json<T>(url: string, signal?: AbortSignal): Promise<T> {
    const res = await this.request(url, signal);
    try {
      return (await res.json()) as T;
    } catch (e) {
      throw new ApiError(`invalid JSON from ${url}: ${String(e)}`, res.status, url);
    }
  }

  health(signal?: AbortSignal): Promise<{ ok: boolean; version: string }> {
    return this.json(this.url('health'), signal);
  }

  async planet(planet: PlanetChoice = {}, signal?: AbortSignal): Promise<PlanetInfo> {
    const info = await this.json<PlanetInfo>(this.url('planet', planet), signal);
    if (!info || info.format !== 'pmc-planet' || info.version !== 1) {
      throw new ApiError(
        `unexpected /planet response (format ${String(info?.format)}, version ${String(info?.version)})`,
        200,
        this.url('planet', planet),
      );
    }
    return info;
  }

  chunks(
    planet: PlanetChoice,
    at: Vec3Tuple,
    range: number,
    limit = 4096,
    signal?: AbortSignal,
  ): Promise<ChunkList> {
    return this.json(
      this.url('chunks', planet, { x: at[0], y: at[1], z: at[2], range, limit }),
      signal,
    );
  }

  /** The path of one chunk mesh (`chunk/<face>/<level>/<i>/<j>/<k>`). */
  chunkUrl(planet: PlanetChoice, key: string): string {
    return this.url(`chunk/${key}`, planet);
  }

  async chunk(planet: PlanetChoice, key: string, signal?: AbortSignal): Promise<DecodedChunk> {
    const url = this.chunkUrl(planet, key);
    const res = await this.request(url, signal);
    const bytes = await res.arrayBuffer();
    try {
      return decodeChunk(bytes);
    } catch (e) {
      throw new ApiError(`chunk ${key}: ${(e as Error).message}`, res.status, url);
    }
  }

  stats(signal?: AbortSignal): Promise<Record<string, number>> {
    return this.json(this.url('stats'), signal);
  }
}
