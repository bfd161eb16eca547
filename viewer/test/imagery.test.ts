import { describe, expect, it } from 'vitest';
import { ImageryError, halvedSize, imageryCellMetres, imageryUv, parseImagery, type ImageryInfo } from '../src/imagery';

const good: ImageryInfo = { url: '/api/v1/imagery', extent: [-180, 180, -90, 90], width: 2048, height: 1024, digest: 'ab12' };

describe('parseImagery', () => {
  it('reads the imagery block, and none when absent or null', () => {
    expect(parseImagery({ imagery: good })).toEqual(good);
    expect(parseImagery({})).toBeNull();
    expect(parseImagery({ imagery: null })).toBeNull();
  });

  it.each([
    ['not an object', { imagery: 'earth.jpg' }, /expected an object or null/],
    ['an array', { imagery: [good] }, /expected an object or null/],
    ['no url', { imagery: { ...good, url: '' } }, /url/],
    ['a url that is a number', { imagery: { ...good, url: 7 } }, /url/],
    ['three numbers of extent', { imagery: { ...good, extent: [0, 1, 2] } }, /four finite numbers/],
    ['a NaN in the extent', { imagery: { ...good, extent: [0, Number.NaN, 0, 1] } }, /four finite numbers/],
    ['a string in the extent', { imagery: { ...good, extent: ['-180', 180, -90, 90] } }, /four finite numbers/],
    ['east before west', { imagery: { ...good, extent: [10, -10, -90, 90] } }, /east must exceed west/],
    ['more than a turn', { imagery: { ...good, extent: [-180, 190, -90, 90] } }, /at most 360/],
    ['north before south', { imagery: { ...good, extent: [-180, 180, 10, -10] } }, /south < north/],
    ['past the pole', { imagery: { ...good, extent: [-180, 180, -91, 90] } }, /south < north/],
    ['a fractional width', { imagery: { ...good, width: 20.5 } }, /width/],
    ['no height', { imagery: { ...good, height: undefined } }, /height/],
    ['a zero height', { imagery: { ...good, height: 0 } }, /height/],
    ['a numeric digest', { imagery: { ...good, digest: 12 } }, /digest/],
  ])('refuses %s with an error that says so', (_what, planet, message) => {
    expect(() => parseImagery(planet)).toThrow(ImageryError);
    expect(() => parseImagery(planet)).toThrow(message);
  });

  it('refuses a planet description that is not an object', () => {
    expect(() => parseImagery(null)).toThrow(/not an object/);
    expect(() => parseImagery('x')).toThrow(ImageryError);
  });
});

describe('imageryUv', () => {
  it('maps the extent onto the picture: u from the west edge, v from the north edge', () => {
    expect(imageryUv(good, 90, -180)).toEqual([0, 0]);
    expect(imageryUv(good, 0, 0)).toEqual([0.5, 0.5]);
    expect(imageryUv(good, -90, 90)).toEqual([0.75, 1]);
  });

  it('has no seam at the antimeridian: longitudes taken modulo 360', () => {
    const a = imageryUv(good, 10, 179.999)!;
    const b = imageryUv(good, 10, -180.001)!;
    expect(a[0]).toBeCloseTo(b[0], 9);
    expect(imageryUv(good, 10, 450)![0]).toBeCloseTo(imageryUv(good, 10, 90)![0], 12);
    expect(imageryUv(good, 10, 180)![0]).toBe(0);
  });

  it('is null outside a partial extent, and wraps a region across the antimeridian', () => {
    const pacific = { extent: [160, 200, -10, 10] as [number, number, number, number] };
    expect(imageryUv(pacific, 0, 170)![0]).toBeCloseTo(0.25, 12);
    expect(imageryUv(pacific, 0, -170)![0]).toBeCloseTo(0.75, 12);
    expect(imageryUv(pacific, 0, 0)).toBeNull();
    expect(imageryUv(pacific, 20, 170)).toBeNull();
  });

  it('sizes a cell on the ground', () => {
    expect(imageryCellMetres(good, 6_371_000)).toBeCloseTo((Math.PI * 6_371_000) / 1024, 6);
  });
});

describe('halvedSize', () => {
  it('halves a picture larger than the GPU takes as the server does (?max=)', () => {
    expect(halvedSize(2048, 1024, 16384)).toEqual([2048, 1024]);
    expect(halvedSize(21600, 10800, 16384)).toEqual([10800, 5400]);
    expect(halvedSize(43201, 21601, 8192)).toEqual([5400, 2700]);
    expect(halvedSize(5, 3, 1)).toEqual([1, 1]);
  });
});
