// REST access for the dashboard. Every call goes to the shore server that served the page; the
// HttpOnly cookie set at login carries the token, so no header is needed here.

export class ApiError extends Error {
  constructor(status, message) {
    super(message);
    this.status = status;
  }
}

export async function api(path, { method = 'GET', body } = {}) {
  const init = { method, headers: {} };
  if (body !== undefined) {
    init.headers['Content-Type'] = 'application/json';
    init.body = JSON.stringify(body);
  }
  const res = await fetch(`/api/v1${path}`, init);
  if (res.status === 204) return null;
  const text = await res.text();
  let data = null;
  try {
    data = text ? JSON.parse(text) : null;
  } catch {
    data = { error: text };
  }
  if (!res.ok) throw new ApiError(res.status, data?.error ?? `HTTP ${res.status}`);
  return data;
}

// What this shore server offers, read from its OpenAPI document (open without a token). The
// views ask before calling an endpoint, so an older server shows "not available" instead of
// a failed request.
const paths = new Set();
export async function loadCapabilities() {
  try {
    const res = await fetch('/api/v1/openapi.json');
    const doc = await res.json();
    for (const p of Object.keys(doc.paths ?? {})) paths.add(p.replace(/^\/api\/v1/, ''));
  } catch {
    // No description: assume the walking-skeleton API (boats and stream).
    ['/boats', '/stream'].forEach((p) => paths.add(p));
  }
}
export function has(path) {
  return paths.has(path);
}

export function q(params) {
  const s = new URLSearchParams();
  for (const [k, v] of Object.entries(params)) if (v !== undefined && v !== null) s.set(k, v);
  const str = s.toString();
  return str ? `?${str}` : '';
}
