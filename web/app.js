// Telltale dashboard: hash routes over one live feed.
//   #/fleet            every boat as a card (default)
//   #/map              the fleet on a map: positions, course arrows, two-minute trails
//   #/boat/ID          one boat: live charts, alarms, alarm rules editor (coach)
//   #/review?boat=ID&session=N&vs=M   session review, overlay, export
//   #/wearables        athletes: steps, cadence, gait, pose, dead-reckoned track
//   #/import           log files from other instruments, dropped or picked, uploaded with progress
// Login: open the page at /#token=TOKEN once; the token is exchanged for an HttpOnly cookie and
// removed from the address bar.
import { api, has, loadCapabilities } from './js/api.js';
import { mountBoat } from './js/boat.js';
import { mountFleet } from './js/fleet.js';
import { mountImport } from './js/import.js';
import { mountMap } from './js/map.js';
import { Live } from './js/live.js';
import { mountReview } from './js/review.js';
import { beep, setSound, soundOn } from './js/sound.js';
import { mountWearables } from './js/wearable.js';

const view = document.getElementById('view');
const connection = document.getElementById('connection');
const message = document.getElementById('message');
const soundButton = document.getElementById('sound');
const live = new Live();
let role = sessionStorage.getItem('telltale.role') ?? 'unknown';
let unmount = () => {};

const ROUTES = { fleet: mountFleet, map: mountMap, boat: mountBoat, review: mountReview, wearables: mountWearables,
  import: mountImport };

function showMessage(text) {
  message.textContent = text;
  message.hidden = !text;
}

function navigate(hash) {
  if (location.hash === hash) route();
  else location.hash = hash;
}

function route() {
  const [path, query = ''] = location.hash.replace(/^#\/?/, '').split('?');
  const [name, ...params] = path.split('/');
  const mount = ROUTES[name] ?? mountFleet;
  const current = ROUTES[name] ? name : 'fleet';
  unmount();
  view.replaceChildren();
  view.dataset.view = current;
  document.querySelectorAll('nav a').forEach((a) =>
    a.toggleAttribute('aria-current', a.dataset.route === current));
  document.title = `Telltale — ${current}`;
  unmount = mount(view, { live, role, params, query: new URLSearchParams(query), navigate }) ?? (() => {});
}

async function login() {
  const m = /(?:^#|&)token=([^&]+)/.exec(location.hash);
  if (!m) return;
  const token = decodeURIComponent(m[1]);
  // `&view=map` (the link the shore prints) opens that view once logged in.
  const v = /&view=([a-z]+)/.exec(location.hash);
  history.replaceState(null, '', `${location.pathname}${location.search}#/${v ? v[1] : 'fleet'}`);
  const res = await fetch('/api/v1/login', { method: 'POST', headers: { Authorization: `Bearer ${token}` } });
  if (!res.ok) {
    showMessage('That token was refused. Ask the coach for a new link.');
    return;
  }
  role = (await res.json()).role ?? role;
  sessionStorage.setItem('telltale.role', role);
}

// The alarm sound: a beep when a boat enters warn or alarm, repeated every 5 s while any boat
// is in alarm and its alarm has not been silenced by the coach.
function watchAlarms() {
  const last = new Map();
  const silenced = new Set();
  live.addEventListener('boat', (e) => {
    const b = e.detail;
    const before = last.get(b.id) ?? 'normal';
    last.set(b.id, b.alarm_state);
    if (b.alarm_state !== before && b.alarm_state !== 'normal') beep(b.alarm_state);
    if (b.alarm_state === 'normal') silenced.delete(b.id);
  });
  live.addEventListener('alarm', (e) => {
    if (e.detail.phase === 'silenced') silenced.add(e.detail.boat_id);
  });
  setInterval(() => {
    if ([...last].some(([id, s]) => s === 'alarm' && !silenced.has(id))) beep('alarm');
  }, 5000);
  soundButton.addEventListener('click', () => {
    setSound(!soundOn());
    soundButton.setAttribute('aria-pressed', String(soundOn()));
    soundButton.textContent = soundOn() ? 'Sound on' : 'Sound off';
  });
}

async function start() {
  await loadCapabilities();
  await login();
  let boats;
  try {
    boats = await api('/boats');
  } catch (err) {
    if (err.status !== 401) throw err;
    connection.dataset.state = 'lost';
    connection.textContent = 'not logged in';
    showMessage('Open the link the shore server printed (it ends in #token=…) to log in.');
    return;
  }
  if (has('/me')) {
    role = (await api('/me')).role ?? role;
    sessionStorage.setItem('telltale.role', role);
  }
  document.body.dataset.role = role;
  boats.forEach((b) => live.addBoat(b));
  live.addEventListener('state', (e) => {
    connection.dataset.state = e.detail;
    connection.textContent = e.detail === 'live' ? 'live' : 'reconnecting…';
  });
  live.start();
  watchAlarms();
  window.addEventListener('hashchange', route);
  route();
}

start().catch((err) => {
  connection.dataset.state = 'lost';
  connection.textContent = 'error';
  showMessage(String(err));
});
