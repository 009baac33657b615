// Optional alarm sound (Web Audio, no files). Browsers only allow audio after a user gesture,
// so the sound is off until the user switches it on with the button.

let ctx = null;
let enabled = false;

export function setSound(on) {
  enabled = on;
  if (on && !ctx) ctx = new AudioContext();
  if (on) ctx.resume();
  if (on) beep('warn');
}

export function soundOn() {
  return enabled;
}

// Two short beeps: high for an alarm, lower for a warning.
export function beep(level) {
  if (!enabled || !ctx) return;
  const freq = level === 'alarm' ? 1760 : 880;
  const now = ctx.currentTime;
  for (const start of [0, 0.25]) {
    const osc = ctx.createOscillator();
    const gain = ctx.createGain();
    osc.type = 'square';
    osc.frequency.value = freq;
    gain.gain.setValueAtTime(0.0001, now + start);
    gain.gain.exponentialRampToValueAtTime(0.3, now + start + 0.01);
    gain.gain.exponentialRampToValueAtTime(0.0001, now + start + 0.18);
    osc.connect(gain).connect(ctx.destination);
    osc.start(now + start);
    osc.stop(now + start + 0.2);
  }
}
