// Each boat's last manoeuvre for the fleet cards: every POLL_MS the sessions active in the last
// minute, and for each the manoeuvres from a little before the last poll on
// (GET /sessions/{id}/manoeuvres?from=T reads only the data from 45 s before T, never the whole
// session). A manoeuvre is listed by the shore ~15 s after its t0; its distance lost is final
// once the data reaches t0 + 20 s (the end of its window), until then the card says "measuring".
import { api, q } from './api.js';
import { isoToSeconds } from './util.js';

const POLL_MS = 5000;
const FIRST_LOOK_S = 600; // on opening the fleet view: the last manoeuvre of the last 10 minutes
const LOOK_S = 90; // later polls: a manoeuvre is listed well within this after its t0
const LOST_WINDOW_END_S = 20; // distance_lost_m: t0 - 10 .. t0 + 20 s

// Calls onManoeuvre(boatId, {kind, t0, distance_lost_m, final, session}) whenever a boat's
// last manoeuvre appears or changes. Returns a stop function.
export function watchManoeuvres(onManoeuvre) {
  const last = new Map(); // boat id -> the manoeuvre shown
  const seen = new Set(); // session ids polled before
  let stopped = false;
  let timer = 0;
  async function poll() {
    const now = Date.now() / 1000;
    try {
      const sessions = await api(`/sessions${q({ from: (now - 60).toFixed(3) })}`);
      // The newest session of each boat.
      const newest = new Map();
      for (const s of sessions) if (!newest.has(s.boat_id) || newest.get(s.boat_id).start_t_s < s.start_t_s) newest.set(s.boat_id, s);
      await Promise.all([...newest.values()].map(async (s) => {
        const since = Math.max(s.start_t_s, now - (seen.has(s.id) ? LOOK_S : FIRST_LOOK_S));
        const r = await api(`/sessions/${s.id}/manoeuvres${q({ from: since.toFixed(3) })}`).catch(() => null);
        if (!r || stopped) return;
        seen.add(s.id);
        const dataTo = r.data_to_utc ? isoToSeconds(r.data_to_utc) : -Infinity;
        const m = r.manoeuvres.reduce((a, b) => (!a || isoToSeconds(b.t_utc) > isoToSeconds(a.t_utc) ? b : a), null);
        if (!m) return;
        const t0 = isoToSeconds(m.t_utc);
        const prev = last.get(s.boat_id);
        if (prev && prev.t0 > t0 + 1) return; // an older one than the card shows
        const next = { kind: m.kind, t0, distance_lost_m: m.distance_lost_m, turn_deg: m.turn_deg, session: s.id,
          final: dataTo >= t0 + LOST_WINDOW_END_S };
        if (prev && prev.t0 === next.t0 && prev.final === next.final && prev.distance_lost_m === next.distance_lost_m) return;
        last.set(s.boat_id, next);
        onManoeuvre(s.boat_id, next);
      }));
    } catch {
      // The next poll tries again; the cards keep what they show.
    }
    if (!stopped) timer = setTimeout(poll, POLL_MS);
  }
  poll();
  return () => {
    stopped = true;
    clearTimeout(timer);
  };
}
