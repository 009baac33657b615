// Positions on the water in local metres: an equirectangular projection around a reference
// point (good to centimetres over a race area of a few km), speed units and the heel colours
// shared by the fleet map and the session review. No tiles, no internet.

const R_M = 6371008.8; // mean Earth radius
const RAD = Math.PI / 180;
export const KNOTS_PER_M_S = 3600 / 1852;

// A projection centred on (lat0, lon0): east and north in metres.
export function projection(lat0, lon0) {
  const kx = Math.cos(lat0 * RAD) * R_M * RAD;
  const ky = R_M * RAD;
  return {
    lat0,
    lon0,
    toXY: (lat, lon) => [(lon - lon0) * kx, (lat - lat0) * ky],
    toLatLon: (x, y) => [lat0 + y / ky, lon0 + x / kx],
  };
}

export function hasFix(b) {
  return Number.isFinite(b?.lat_deg) && Number.isFinite(b?.lon_deg);
}

export function knots(mps) {
  return Number.isFinite(mps) ? mps * KNOTS_PER_M_S : null;
}

// "6.3 kn" and "3.2 m/s", or dashes without a fix.
export function speedText(mps) {
  if (!Number.isFinite(mps)) return { kn: '–', ms: '– m/s' };
  return { kn: knots(mps).toFixed(1), ms: `${mps.toFixed(1)} m/s` };
}

// A round length (1, 2 or 5 x 10^n metres) close to `target` metres, for scale bars.
export function niceMetres(target) {
  const p = 10 ** Math.floor(Math.log10(Math.max(target, 1e-3)));
  const f = target / p;
  return (f >= 5 ? 5 : f >= 2 ? 2 : 1) * p;
}

export function metresText(m) {
  return m >= 1000 ? `${(m / 1000).toFixed(m % 1000 ? 1 : 0)} km` : `${m} m`;
}

// Heel colours by |heel| (the track shows the tack by its direction): one band per colour.
export const HEEL_COLOURS = [
  { upTo: 5, color: '#0047ab', label: '0–5°' },
  { upTo: 10, color: '#0a8a3a', label: '5–10°' },
  { upTo: 15, color: '#d08a00', label: '10–15°' },
  { upTo: 20, color: '#c00018', label: '15–20°' },
  { upTo: Infinity, color: '#6a1b9a', label: '> 20°' },
];
export function heelClass(heel) {
  if (!Number.isFinite(heel)) return -1;
  const a = Math.abs(heel);
  return HEEL_COLOURS.findIndex((c) => a < c.upTo);
}

// Index of the first t >= x in a sorted array (xs.length when none).
export function lowerBound(xs, x) {
  let lo = 0;
  let hi = xs.length;
  while (lo < hi) {
    const mid = (lo + hi) >> 1;
    if (xs[mid] < x) lo = mid + 1;
    else hi = mid;
  }
  return lo;
}
