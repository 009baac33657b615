// The live feed: one EventSource for the whole page. Keeps the latest state of every boat and
// athlete and the recent history each view draws from, and tells the views what changed.

const HISTORY_S = 300; // the boat view charts five minutes; the fleet sparkline one

export class Live extends EventTarget {
  constructor() {
    super();
    this.boats = new Map(); // id -> {boat, receivedAt (ms, page clock), hist: {t, heel, pitch, heading}}
    this.athletes = new Map(); // id -> {athlete, receivedAt, track: {t, x, y}}
    this.alarms = new Map(); // event id -> Event (latest phase)
    this.state = 'connecting';
  }

  start() {
    this.source = new EventSource('/api/v1/stream');
    this.source.addEventListener('open', () => this.setState('live'));
    this.source.addEventListener('error', () => this.setState('lost'));
    this.source.addEventListener('sample', (e) => this.addBoat(JSON.parse(e.data)));
    this.source.addEventListener('alarm', (e) => this.addAlarm(JSON.parse(e.data)));
    this.source.addEventListener('wearable', (e) => this.addAthlete(JSON.parse(e.data)));
    // A boat's manoeuvre, found or final (manoeuvre_live.js keeps each boat's last).
    this.source.addEventListener('manoeuvre', (e) => this.emit('manoeuvre', JSON.parse(e.data)));
    this.source.addEventListener('overflow', () => this.emit('overflow', null));
  }

  setState(state) {
    this.state = state;
    this.emit('state', state);
  }

  emit(type, detail) {
    this.dispatchEvent(new CustomEvent(type, { detail }));
  }

  addBoat(boat) {
    let entry = this.boats.get(boat.id);
    if (!entry) {
      entry = { boat, receivedAt: 0, hist: { t: [], heel: [], pitch: [], heading: [] } };
      this.boats.set(boat.id, entry);
    }
    const t = boat.t_utc_ns / 1e9;
    const h = entry.hist;
    // The snapshot at (re)connect repeats the last sample: keep time strictly increasing.
    if (!h.t.length || t > h.t[h.t.length - 1]) {
      h.t.push(t);
      h.heel.push(boat.heel_deg);
      h.pitch.push(boat.pitch_deg);
      h.heading.push(boat.heading_deg);
      if (h.t[0] < t - HISTORY_S - 30) trim(h, t - HISTORY_S);
    }
    entry.boat = boat;
    entry.receivedAt = Date.now();
    this.emit('boat', boat);
  }

  // Fills the history from recorded samples (the boat view asks for the last minutes).
  backfill(id, data) {
    const entry = this.boats.get(id);
    if (!entry || !data?.t_s?.length) return;
    const h = entry.hist;
    const first = h.t.length ? h.t[0] : Infinity;
    const n = data.t_s.findIndex((t) => t >= first);
    const take = n < 0 ? data.t_s.length : n;
    h.t.unshift(...data.t_s.slice(0, take));
    h.heel.unshift(...data.heel_deg.slice(0, take));
    h.pitch.unshift(...data.pitch_deg.slice(0, take));
    h.heading.unshift(...(data.heading_deg ?? data.t_s.map(() => null)).slice(0, take));
  }

  addAlarm(event) {
    this.alarms.set(event.id, event);
    this.emit('alarm', event);
  }

  addAthlete(athlete) {
    let entry = this.athletes.get(athlete.id);
    if (!entry) {
      entry = { athlete, receivedAt: 0, track: { t: [], x: [], y: [] } };
      this.athletes.set(athlete.id, entry);
    }
    const tr = entry.track;
    const t = Date.parse(athlete.last_sample_time) / 1000;
    if (Number.isFinite(athlete.x_m) && (!tr.t.length || t > tr.t[tr.t.length - 1])) {
      tr.t.push(t);
      tr.x.push(athlete.x_m);
      tr.y.push(athlete.y_m);
    }
    entry.athlete = athlete;
    entry.receivedAt = Date.now();
    this.emit('wearable', athlete);
  }

  // A boat is silent when the shore says so or when nothing arrived for 2 s (the shore stops
  // sending samples for a silent boat, so the page must notice on its own).
  isStale(entry) {
    return entry.boat.stale || Date.now() - entry.receivedAt > 2000;
  }
}

function trim(h, from) {
  const i = h.t.findIndex((t) => t >= from);
  if (i > 0) for (const k of Object.keys(h)) h[k].splice(0, i);
}
