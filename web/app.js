// Telltale fleet view: one card per boat, updated live from /api/v1/stream (Server-Sent Events).
// Login: open the page at /#token=TOKEN once; the token is exchanged for an HttpOnly cookie and
// removed from the address bar.

const fleet = document.getElementById('fleet');
const template = document.getElementById('boat-card');
const connection = document.getElementById('connection');
const message = document.getElementById('message');
const cards = new Map();

function fmt(v) {
  return v === null || v === undefined ? '–' : `${v >= 0 ? '+' : ''}${v.toFixed(1)}°`;
}

function setConnection(state, text) {
  connection.dataset.state = state;
  connection.textContent = text;
}

function showMessage(text) {
  message.textContent = text;
  message.hidden = !text;
}

function ledBar(bar, lit, count) {
  if (bar.childElementCount !== count) {
    bar.replaceChildren(...Array.from({ length: count }, () => {
      const led = document.createElement('span');
      led.className = 'led';
      return led;
    }));
  }
  [...bar.children].forEach((led, i) => led.classList.toggle('on', i < lit));
}

function card(id) {
  let el = cards.get(id);
  if (el) return el;
  el = template.content.firstElementChild.cloneNode(true);
  el.dataset.boat = id;
  el.querySelector('.boat-id').textContent = id;
  cards.set(id, el);
  // Keep cards sorted by boat id.
  const after = [...cards.keys()].sort().find((k) => k > id);
  fleet.insertBefore(el, after ? cards.get(after) : null);
  return el;
}

function render(boat) {
  const el = card(boat.id);
  el.dataset.alarm = boat.alarm_state;
  el.dataset.stale = String(boat.stale);
  el.querySelector('.heel').textContent = fmt(boat.heel_deg);
  el.querySelector('.pitch').textContent = fmt(boat.pitch_deg);
  // Seen from astern: heel > 0 (starboard down) turns the hull clockwise on screen.
  const heel = boat.heel_deg ?? 0;
  el.querySelector('.hull-heel').setAttribute('transform', `rotate(${heel.toFixed(1)})`);
  const leds = boat.leds ?? { left: 0, right: 0, up: 0, down: 0, count: 6 };
  const count = leds.count || 6;
  for (const side of ['left', 'right', 'up', 'down']) {
    ledBar(el.querySelector(`.bar.${side}`), leds[side], count);
  }
  el.querySelector('.meta').textContent =
    `${boat.last_sample_time.slice(11, 19)} UTC · #${boat.seq}` +
    (boat.heading_deg === null ? '' : ` · ${boat.heading_deg.toFixed(0)}°`);
}

async function login() {
  const m = /(?:^#|&)token=([^&]+)/.exec(location.hash);
  if (!m) return;
  const token = decodeURIComponent(m[1]);
  history.replaceState(null, '', location.pathname + location.search);
  const res = await fetch('/api/v1/login', {
    method: 'POST',
    headers: { Authorization: `Bearer ${token}` },
  });
  if (!res.ok) showMessage('That token was refused. Ask the coach for a new link.');
}

async function start() {
  await login();
  const res = await fetch('/api/v1/boats');
  if (res.status === 401) {
    setConnection('lost', 'not logged in');
    showMessage('Open the link the shore server printed (it ends in #token=…) to log in.');
    return;
  }
  (await res.json()).forEach(render);
  const stream = new EventSource('/api/v1/stream');
  stream.addEventListener('open', () => setConnection('live', 'live'));
  stream.addEventListener('error', () => setConnection('lost', 'reconnecting…'));
  stream.addEventListener('sample', (e) => render(JSON.parse(e.data)));
}

start().catch((err) => {
  setConnection('lost', 'error');
  showMessage(String(err));
});
