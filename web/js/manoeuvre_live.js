// Each boat's last manoeuvre for the fleet cards. The shore finds every live boat's manoeuvres
// itself, once, as the samples arrive, and pushes each on the live stream (event "manoeuvre",
// live.js) twice: when found (its distance lost still measuring) and when final. The page never
// polls for them: the cards follow the stream. What happened before the page listened (on
// opening the fleet view, after a reconnect or a dropped event) comes from one REST call per boat
// active in the last 10 minutes.
import { api, q } from './api.js';
import { isoToSeconds } from './util.js';

const FIRST_LOOK_S = 600; // the last manoeuvre of the last 10 minutes
const SAME_S = 12; // two reports of one manoeuvre: t0s this close (the shore's kSameManoeuvreS)
const FINAL_AFTER_S = 25; // a REST row is final once the data reaches t0 + 25 s

// Calls onManoeuvre(boatId, {kind, t0, distance_lost_m, turn_deg, final}) whenever a boat's last
// manoeuvre appears or changes. `fill`: whether the shore offers /sessions/{id}/manoeuvres for
// what came before. Returns a stop function.
export function watchManoeuvres(live, onManoeuvre, { fill = true } = {}) {
  const last = new Map(); // boat id -> the manoeuvre shown
  let stopped = false;

  function show(boatId, m) {
    const prev = last.get(boatId);
    if (prev) {
      const same = Math.abs(prev.t0 - m.t0) < SAME_S;
      if (!same && prev.t0 > m.t0) return; // an older one than the card shows
      if (same && prev.final && !m.final) return; // measured already
      if (same && prev.final === m.final && prev.kind === m.kind && prev.t0 === m.t0
        && prev.distance_lost_m === m.distance_lost_m) return;
    }
    last.set(boatId, m);
    onManoeuvre(boatId, m);
  }

  function onEvent(e) {
    const r = e.detail;
    show(r.boat_id, { kind: r.kind, t0: isoToSeconds(r.t_utc), distance_lost_m: r.distance_lost_m,
      turn_deg: r.turn_deg, final: r.final === true });
  }

  async function fillIn() {
    if (!fill || stopped) return;
    const now = Date.now() / 1000;
    try {
      const sessions = await api(`/sessions${q({ from: (now - FIRST_LOOK_S).toFixed(3) })}`);
      const newest = new Map(); // the newest session of each boat
      for (const s of sessions) if (!newest.has(s.boat_id) || newest.get(s.boat_id).start_t_s < s.start_t_s) newest.set(s.boat_id, s);
      await Promise.all([...newest.values()].map(async (s) => {
        const since = Math.max(s.start_t_s, now - FIRST_LOOK_S);
        const r = await api(`/sessions/${s.id}/manoeuvres${q({ from: since.toFixed(3) })}`).catch(() => null);
        if (!r || stopped) return;
        const m = r.manoeuvres.reduce((a, b) => (!a || isoToSeconds(b.t_utc) > isoToSeconds(a.t_utc) ? b : a), null);
        if (!m) return;
        const t0 = isoToSeconds(m.t_utc);
        const dataTo = r.data_to_utc ? isoToSeconds(r.data_to_utc) : -Infinity;
        show(s.boat_id, { kind: m.kind, t0, distance_lost_m: m.distance_lost_m, turn_deg: m.turn_deg,
          final: dataTo >= t0 + FINAL_AFTER_S });
      }));
    } catch {
      // The stream carries on; the cards keep what they show.
    }
  }

  let lost = false;
  function onState(e) {
    if (e.detail === 'lost') lost = true;
    if (e.detail === 'live' && lost) {
      lost = false;
      fillIn(); // the reports pushed while the stream was down
    }
  }
  live.addEventListener('manoeuvre', onEvent);
  live.addEventListener('overflow', fillIn);
  live.addEventListener('state', onState);
  fillIn();
  return () => {
    stopped = true;
    live.removeEventListener('manoeuvre', onEvent);
    live.removeEventListener('overflow', fillIn);
    live.removeEventListener('state', onState);
  };
}
