// SPDX-License-Identifier: Apache-2.0
// The wirefish dashboard: a Foxglove WebSocket client (foxglove.sdk.v1) of `wirefish view`.
// Topics arrive as CDR with their ros2msg schemas and are decoded here; cmd_vel goes out as
// JSON on the one client channel the server accepts; start, stop and retune_gait are the
// server's services. `window.wirefish` holds the live values (what the browser test reads).
import { FoxgloveClient } from '@foxglove/ws-protocol';
import { parse } from '@foxglove/rosmsg';
import { MessageReader } from '@foxglove/rosmsg2-serialization';
import uPlot from 'uplot';
import { COUNTERS, health, linkState, number, observedRate, text } from './board.js';

// Either name of the protocol: the view accepts both.
const SUBPROTOCOLS = ['foxglove.sdk.v1', 'foxglove.websocket.v1'];
const KEPT = 100; // refusals, errors and retune reports kept (the newest)
const WINDOW_S = 15; // seconds of history in the time plots
const DRIVE_HZ = 10; // cmd_vel rate while driving (the planner's timeout is 0.5 s)
const SPEED_STEP = 0.05; // m/s, as `wirefish drive`
const TURN_STEP = 0.1; // rad/s
const SLEW_WINDOW_S = 0.25; // servo_state kept for the observed failsafe slew
const SLEW_SAMPLES = 200; // at most this many of them (1 kHz servo_state would be 250)
const WANTED = ['servo_cmd', 'servo_state', 'body_wave', 'planner_state', 'speed_estimate',
  'sim/ground_truth', 'battery', 'cmd_vel', '/diagnostics', '/tf', '/tf_static', 'view/retune'];

const live = {
  connected: false, counts: {}, latest: {}, plots: {}, drive: { speed: 0, turn: 0 },
  retune: null, retuneLog: [], refusals: [], errors: [], estimates: [], topdown: null,
  board: null, boardLog: [],
};
// A bounded log: the newest KEPT entries (a flood of statuses or errors cannot grow the page).
function keep(list, entry) {
  list.push(entry);
  if (list.length > KEPT) list.splice(0, list.length - KEPT);
}
window.wirefish = live;
// The panels' pure functions, for a look at values no fish of the test graph sends (a fault).
live.boardView = { linkState, health };

const $ = (id) => document.getElementById(id);
const stampS = (s) => s.sec + s.nanosec * 1e-9;
const fixed = (v, n = 2) => (Number.isFinite(v) ? v.toFixed(n) : '-');

// --- ring buffers of the time plots ---------------------------------------------------------
class Series {
  constructor(names) { this.t = []; this.v = names.map(() => []); }
  push(t, values) {
    this.t.push(t); values.forEach((x, i) => this.v[i].push(Number.isFinite(x) ? x : null));
    const cut = this.t.findIndex((x) => x >= t - WINDOW_S);
    if (cut > 0) { this.t.splice(0, cut); this.v.forEach((a) => a.splice(0, cut)); }
  }
  data() { return [this.t, ...this.v]; }
}

// Two series sampled at their own times as one table with a shared x (null where a series has
// no sample): what uPlot draws.
function merged(a, b) {
  const t = [...new Set([...a.t, ...b.t])].sort((x, y) => x - y);
  const at = (s) => { const m = new Map(s.t.map((x, i) => [x, s.v[0][i]])); return t.map((x) => (m.has(x) ? m.get(x) : null)); };
  return [t, at(a), at(b)];
}

function timePlot(id, title, labels, colours, unit, extra = []) {
  const opts = {
    title, width: 420, height: 220,
    scales: { x: { time: true } },
    series: [{}, ...labels.map((label, i) => ({ label, stroke: colours[i], width: 1.5, ...(extra[i] || {}) }))],
    axes: [{}, { label: unit }],
  };
  const plot = new uPlot(opts, [[], ...labels.map(() => [])], $(id));
  return plot;
}

const servo = new Series(['cmd 1', 'state 1', 'cmd 2', 'state 2']);
const heading = new Series(['target', 'measured']);
// The speed estimate comes once per tail beat: it is plotted at its own stamps (steps and
// points), never repeated at the ground truth's rate as if it were live.
const estimate = new Series(['estimate']);
const truth = new Series(['ground truth']);
let plots = null;
let wave = { q: [], y: [], yd: [] };

function makePlots() {
  plots = {
    servo: timePlot('plot-servo', '', ['cmd 1', 'state 1', 'cmd 2', 'state 2'],
      ['#1565c0', '#90caf9', '#c62828', '#ef9a9a'], 'rad'),
    heading: timePlot('plot-heading', '', ['target', 'measured'], ['#6a1b9a', '#26a69a'], 'rad'),
    speed: timePlot('plot-speed', '', ['estimate', 'ground truth'], ['#ef6c00', '#2e7d32'],
      'm/s', [{ paths: uPlot.paths.stepped({ align: 1 }), spanGaps: true,
        points: { show: true, size: 6 } }, {}]),
    // The tail from plate I (q = 0) to the tip, whatever the samples (none after a stop):
    // an axis that auto-ranged on nothing jumped to 0-100 m.
    wave: new uPlot({
      width: 420, height: 220,
      scales: {
        x: { time: false, range: (_u, _min, max) => [0, Number.isFinite(max) && max > 0 ? max : 0.24] },
        y: { range: (_u, min, max) => { const r = Math.max(Math.abs(min) || 0, Math.abs(max) || 0, 0.02) * 1.1; return [-r, r]; } },
      },
      series: [{ label: 'q (m)' }, { label: 'y', stroke: '#1565c0', width: 2 },
        { label: 'desired', stroke: '#2e7d32', width: 1, dash: [4, 4] }],
      axes: [{ label: 'q (m)' }, { label: 'm' }],
    }, [[], [], []], $('plot-wave')),
  };
  live.plots = plots;
}

// --- the fish from above ----------------------------------------------------------------------
const fish = { pose: null, trail: [], tailBase: -0.29 };

function drawTopdown() {
  const canvas = $('topdown');
  const g = canvas.getContext('2d');
  g.clearRect(0, 0, canvas.width, canvas.height);
  if (!fish.pose) return;
  const pts = fish.trail.length ? fish.trail : [[fish.pose.x, fish.pose.y]];
  let [minX, maxX, minY, maxY] = [Infinity, -Infinity, Infinity, -Infinity];
  for (const [x, y] of pts) {
    minX = Math.min(minX, x); maxX = Math.max(maxX, x); minY = Math.min(minY, y); maxY = Math.max(maxY, y);
  }
  const span = Math.max(maxX - minX, maxY - minY, 1.0) + 0.6;
  const scale = Math.min(canvas.width, canvas.height) / span;
  const cx = (minX + maxX) / 2; const cy = (minY + maxY) / 2;
  // odom x right, y up on the screen
  const px = (x, y) => [canvas.width / 2 + (x - cx) * scale, canvas.height / 2 - (y - cy) * scale];
  g.strokeStyle = '#ddd'; g.lineWidth = 1;
  for (let gx = Math.floor(cx - span); gx <= cx + span; gx += 0.5) {
    const [a] = px(gx, 0); g.beginPath(); g.moveTo(a, 0); g.lineTo(a, canvas.height); g.stroke();
  }
  for (let gy = Math.floor(cy - span); gy <= cy + span; gy += 0.5) {
    const [, b] = px(0, gy); g.beginPath(); g.moveTo(0, b); g.lineTo(canvas.width, b); g.stroke();
  }
  // A distance scale: a bar of a round length near a quarter of the view, labelled.
  const bar = [0.1, 0.2, 0.5, 1, 2, 5, 10, 20, 50].find((m) => m * scale >= canvas.width / 5) || 100;
  g.strokeStyle = '#333'; g.fillStyle = '#333'; g.lineWidth = 2; g.beginPath();
  g.moveTo(10, canvas.height - 12); g.lineTo(10 + bar * scale, canvas.height - 12); g.stroke();
  g.font = '12px sans-serif';
  g.fillText(`${bar} m (grid 0.5 m)`, 10, canvas.height - 18);
  live.topdown = { bar_m: bar, bar_px: bar * scale };
  g.strokeStyle = '#2e7d32'; g.lineWidth = 1.5; g.beginPath();
  pts.forEach(([x, y], i) => { const [a, b] = px(x, y); if (i) g.lineTo(a, b); else g.moveTo(a, b); });
  g.stroke();
  const { x, y, yaw } = fish.pose;
  const c = Math.cos(yaw); const s = Math.sin(yaw);
  const toOdom = (bx, by) => px(x + c * bx - s * by, y + s * bx + c * by);
  // head: the nose to plate I; tail: tail_base points (turned by pi) behind it
  g.strokeStyle = '#555'; g.lineWidth = 6; g.beginPath();
  g.moveTo(...toOdom(0, 0)); g.lineTo(...toOdom(fish.tailBase, 0)); g.stroke();
  if (wave.q.length) {
    g.strokeStyle = '#1565c0'; g.lineWidth = 3; g.beginPath();
    wave.x.forEach((tx, i) => {
      const p = toOdom(fish.tailBase - tx, -wave.y[i]);
      if (i) g.lineTo(...p); else g.moveTo(...p);
    });
    g.stroke();
  }
}

// --- decoding and dispatch -------------------------------------------------------------------
const readers = new Map(); // channel id -> MessageReader | 'json'
const topicOf = new Map(); // subscription id -> relative topic
let ns = '';
const rel = (topic) => (topic.startsWith(`${ns}/`) ? topic.slice(ns.length + 1) : topic);

function onMessage(topic, m) {
  live.counts[topic] = (live.counts[topic] || 0) + 1;
  switch (topic) {
    case 'servo_cmd': {
      const st = live.latest.servo_state;
      servo.push(stampS(m.header.stamp), [m.position[0], st ? st.position[0] : NaN,
        m.position[1], st ? st.position[1] : NaN]);
      live.latest.servo_cmd = { position: Array.from(m.position) };
      break;
    }
    case 'servo_state':
      live.latest.servo_state = { position: Array.from(m.position) };
      recent.push({ t: stampS(m.header.stamp), position: Array.from(m.position) });
      while (recent.length > SLEW_SAMPLES
        || (recent.length > 1 && recent[0].t < recent[recent.length - 1].t - SLEW_WINDOW_S)) recent.shift();
      break;
    case 'body_wave':
      wave = { q: Array.from(m.q), x: Array.from(m.x), y: Array.from(m.y), yd: Array.from(m.y_desired) };
      live.latest.body_wave = { tip_y: wave.y[wave.y.length - 1], desired: wave.yd.length > 0 };
      break;
    case 'planner_state':
      heading.push(stampS(m.header.stamp), [m.heading_target, m.heading_measured]);
      live.latest.planner_state = { mode: m.mode, target_speed: m.target_speed,
        predicted_speed: m.predicted_speed, note: m.note };
      $('v-mode').textContent = m.mode;
      // A manual override (an applied retune, a parameter set) leaves the drive keys without
      // effect until the gait is handed back: offer that where the keys are.
      $('hand-back').hidden = m.mode !== 'manual';
      $('v-target-speed').textContent = fixed(m.target_speed);
      $('v-predicted-speed').textContent = fixed(m.predicted_speed);
      // A manual override (an applied retune, a parameter set): the way back, in the words
      // of the command line and of the button below.
      $('v-note').textContent = m.mode === 'manual'
        ? 'manual override: the drive keys act again once the gait is handed back '
          + "(the 'hand the gait back' button, or wirefish hand-back)"
        : (m.note || m.clamp_reason || '');
      break;
    case 'speed_estimate':
      live.latest.speed_estimate = m.speed;
      estimate.push(stampS(m.header.stamp), [m.speed]);
      keep(live.estimates, { t: stampS(m.header.stamp), speed: m.speed });
      break;
    case '/tf':
      // This fish's odom -> base_link: the virtual fish's ground truth or the real fish's
      // dead reckoning (tf_node), so the top view works on both.
      for (const t of m.transforms) {
        if (t.header.frame_id !== live.config.frames.odom
            || t.child_frame_id !== live.config.frames.base_link) continue;
        const p = t.transform.translation; const q = t.transform.rotation;
        const yaw = Math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z));
        fish.pose = { x: p.x, y: p.y, yaw };
        const last = fish.trail[fish.trail.length - 1];
        if (!last || Math.hypot(last[0] - p.x, last[1] - p.y) > 0.005) fish.trail.push([p.x, p.y]);
        if (fish.trail.length > 3000) fish.trail.shift();
        live.latest.odom = { x: p.x, y: p.y, yaw };
      }
      break;
    case 'sim/ground_truth': {
      const p = m.pose.pose.position;
      truth.push(stampS(m.header.stamp), [m.twist.twist.linear.x]);
      live.latest.ground_truth = { x: p.x, y: p.y, speed: m.twist.twist.linear.x };
      break;
    }
    case 'battery':
      live.latest.battery = { voltage: m.voltage, percentage: m.percentage };
      // The percentage is NaN when the battery does not say (sensor_msgs/BatteryState): blank.
      $('v-battery').textContent = `${fixed(m.voltage)} V`
        + (Number.isFinite(m.percentage) ? ` ${(100 * m.percentage).toFixed(0)} %` : '');
      break;
    case 'cmd_vel': live.latest.cmd_vel = { speed: m.linear.x, turn: m.angular.z }; break;
    case '/diagnostics': {
      // This fish's bridge only: other graphs' bridges publish on the same global topic.
      const link = m.status.find((s) => s.name.startsWith(`${ns}/bridge_node:`));
      if (link) {
        const level = ['OK', 'WARN', 'ERROR', 'STALE'][link.level] || String(link.level);
        live.latest.link = { level, message: link.message };
        $('v-link').textContent = `${level} ${link.message}`;
        showBoard(Object.fromEntries(link.values.map((kv) => [kv.key, kv.value])), link.message);
      }
      break;
    }
    case '/tf_static':
      for (const t of m.transforms) {
        if (t.child_frame_id === live.config.frames.tail_base) fish.tailBase = t.transform.translation.x;
      }
      break;
    case 'view/retune': onRetune(m); break;
    default: break;
  }
}

// --- the link, gait and health panels (what bridge_node reports in /diagnostics) -------------
const recent = []; // servo_state of the last SLEW_WINDOW_S: the failsafe slew as observed

function showBoard(values, message) {
  const state = linkState(values);
  const h = health(values);
  const hostGait = text(values, 'gait_id'); const boardGait = text(values, 'board_gait_id');
  const stream = text(values, 'drive_mode') === 'stream';
  const rate = observedRate(recent);
  let failsafe = '';
  if (stream && state.state === 'failsafe') {
    failsafe = rate !== null && rate > 0.01
      ? `slewing to neutral, ${rate.toFixed(2)} rad/s observed` : 'holding neutral';
  } else if (stream && text(values, 'failsafe') === 'True') {
    failsafe = 'no servo_cmd: the bridge commands neutral';
  } else if (stream && state.state === 'stream') failsafe = 'off';
  const divergence = number(values, 'oscillator_divergence_rad');
  const board = { ...state, drive_mode: text(values, 'drive_mode'), gait_id: hostGait,
    board_gait_id: boardGait, failsafe, health: h };
  if (!live.board || live.board.state !== board.state) keep(live.boardLog, { state: board.state, words: board.words, at: Date.now() });
  live.board = board;
  const badge = $('v-link-badge');
  badge.textContent = state.words; badge.className = `badge ${state.level}`;
  badge.dataset.state = state.state;
  $('v-drive-mode').textContent = board.drive_mode;
  $('v-gait-id').textContent = hostGait || boardGait ? `${hostGait} / ${boardGait}` : '';
  $('v-fish-status').textContent = text(values, 'fish_status');
  $('v-failsafe').textContent = failsafe;
  $('v-divergence').textContent = divergence === null ? '' : `${divergence.toFixed(3)} rad`;
  $('v-link-message').textContent = message;
  $('v-reset-cause').textContent = h.reset_cause;
  $('v-uptime').textContent = h.uptime;
  $('v-clock').textContent = h.clock.words;
  $('v-clock').className = h.clock.fallback ? 'fallback' : '';
  $('v-stack').textContent = h.stack;
  $('v-health-flags').textContent = h.flags;
  const table = $('v-counters');
  if (!table.rows.length) {
    COUNTERS.forEach(([key, label]) => {
      const row = table.insertRow(); const th = document.createElement('th');
      th.textContent = label; row.appendChild(th); row.insertCell().id = `v-${key}`;
    });
  }
  h.counters.forEach(({ key, value }) => { $(`v-${key}`).textContent = value; });
}

// Legends show the latest values while the pointer is not over a plot (uPlot's own legend
// shows '--' without a cursor).
function latestInLegend(plot) {
  const n = plot.data[0].length;
  if (n && (plot.cursor.left == null || plot.cursor.left < 0)) {
    const last = plot.series.map((_s, i) => {
      for (let k = n - 1; k >= 0; k -= 1) if (plot.data[i][k] != null) return k;
      return n - 1;
    });
    plot.setLegend({ idx: n - 1, idxs: last });
  }
}

function refresh() {
  if (!plots) return;
  plots.servo.setData(servo.data());
  plots.heading.setData(heading.data());
  plots.speed.setData(merged(estimate, truth));
  if (wave.q.length && wave.q.every(Number.isFinite)) {
    plots.wave.setData([wave.q, wave.y, wave.yd.length ? wave.yd : wave.q.map(() => null)]);
  }
  Object.values(plots).forEach(latestInLegend);
  drawTopdown();
}

// --- services ---------------------------------------------------------------------------------
const services = new Map(); // name -> id
const calls = new Map(); // call id -> {resolve, reject}
let nextCall = 1;
let client = null;

function callService(name, request) {
  const serviceId = services.get(`${ns}/${name}`);
  if (serviceId === undefined) return Promise.reject(new Error(`no service ${name}`));
  const callId = nextCall++;
  return new Promise((resolve, reject) => {
    calls.set(callId, { resolve, reject });
    client.sendServiceCallRequest({ serviceId, callId, encoding: 'json',
      data: new TextEncoder().encode(JSON.stringify(request)) });
  });
}

// --- driving ----------------------------------------------------------------------------------
let cmdChannel = null;
let driveTimer = null;
let stopped = false;

function sendCmdVel() {
  if (!client || cmdChannel === null) return;
  const { speed: v, turn: w } = live.drive;
  client.sendMessage(cmdChannel, new TextEncoder().encode(JSON.stringify(
    { linear: { x: v, y: 0, z: 0 }, angular: { x: 0, y: 0, z: w } })));
}

function showDrive() {
  $('v-cmd-speed').textContent = fixed(live.drive.speed);
  $('v-cmd-turn').textContent = fixed(live.drive.turn);
}

async function drive(key) {
  const d = live.drive; const lim = live.config;
  if (key === ' ') { stop(); return; }
  if (stopped) {
    stopped = false;
    try { $('v-drive-status').textContent = (await callService('start', {})).message; } catch (e) { keep(live.errors, String(e)); }
  }
  if (key === 'w') d.speed = Math.min(lim.max_speed, +(d.speed + SPEED_STEP).toFixed(3));
  if (key === 's') d.speed = Math.max(0, +(d.speed - SPEED_STEP).toFixed(3));
  if (key === 'a') d.turn = Math.min(lim.max_turn, +(d.turn + TURN_STEP).toFixed(3));
  if (key === 'd') d.turn = Math.max(-lim.max_turn, +(d.turn - TURN_STEP).toFixed(3));
  showDrive();
  sendCmdVel();
  if (!driveTimer) driveTimer = setInterval(sendCmdVel, 1000 / DRIVE_HZ);
}

function stop() {
  // Zero at once and at the drive rate, whatever else fails; the server's stop service also
  // sends a zero cmd_vel before it stops the CPG.
  live.drive.speed = 0; live.drive.turn = 0; stopped = true;
  showDrive(); sendCmdVel();
  if (!driveTimer) driveTimer = setInterval(sendCmdVel, 1000 / DRIVE_HZ);
  callService('stop', {}).then((r) => { $('v-drive-status').textContent = r.message; })
    .catch((e) => { $('v-drive-status').textContent = String(e); });
}

const KEYS = { w: 'w', a: 'a', s: 's', d: 'd', ArrowUp: 'w', ArrowDown: 's', ArrowLeft: 'a',
  ArrowRight: 'd', ' ': ' ' };

function wireControls() {
  document.addEventListener('keydown', (e) => {
    if (e.target.tagName === 'INPUT') return;
    const key = KEYS[e.key];
    if (key) { e.preventDefault(); drive(key); }
  });
  document.querySelectorAll('.pad button[data-key]').forEach((b) => {
    b.addEventListener('click', () => drive(b.dataset.key));
  });
  $('stop').addEventListener('click', stop);
  $('start').addEventListener('click', () => {
    stopped = false;
    callService('start', {}).then((r) => { $('v-drive-status').textContent = r.message; });
  });
  $('hand-back').addEventListener('click', () => {
    callService('follow_commands', {}).then((r) => { $('v-drive-status').textContent = r.message; })
      .catch((err) => { $('v-drive-status').textContent = String(err); });
  });
  $('retune-form').addEventListener('submit', (e) => {
    e.preventDefault();
    const f = new FormData(e.target);
    // Each field checked before anything is sent: 'abc' is not a number (Number('abc') is
    // NaN, which JSON sends as null).
    const problems = [];
    const num = (k, label, whole = false) => {
      const text = String(f.get(k)).trim();
      const v = Number(text);
      if (text === '' || !Number.isFinite(v)) problems.push(`${label} must be a number, got '${text}'`);
      else if (whole && !(Number.isInteger(v) && v >= 0)) problems.push(`${label} must be a whole number >= 0, got '${text}'`);
      return v;
    };
    const request = { wave: { c1: num('c1', 'c1'), c2: num('c2', 'c2'), k: num('k', 'k'),
      frequency_hz: num('frequency_hz', 'f (Hz)') },
    apply: f.get('apply') === 'on', max_iterations: num('max_iterations', 'iterations', true), use_library: false };
    if (problems.length) {
      live.retune = { state: 'invalid', message: problems.join('; ') };
      $('v-retune').textContent = problems.join('; ');
      return;
    }
    live.retune = { state: 'asked' };
    $('v-retune').textContent = 'asked';
    $('retune-progress').value = 0;
    callService('retune_gait', request).then((r) => {
      if (!r.success) { live.retune = { state: 'refused', message: r.message }; $('v-retune').textContent = r.message; }
    }).catch((err) => {
      live.retune = { state: 'refused', message: String(err.message || err) };
      $('v-retune').textContent = String(err.message || err);
    });
  });
}

function onRetune(m) {
  live.retune = m;
  keep(live.retuneLog, m);
  if (m.state === 'running') {
    $('retune-progress').max = Math.max(m.max_iterations, 1);
    $('retune-progress').value = m.iteration;
    $('v-retune').textContent = `iteration ${m.iteration}/${m.max_iterations}, best loss ${fixed(m.best_loss, 4)}`;
  } else if (m.state === 'done') {
    // A refused wave is answered at once with no iteration: no full bar for it.
    $('retune-progress').value = m.success ? $('retune-progress').max : 0;
    $('v-retune').textContent = m.success
      ? `done: ${m.message}; applied ${m.applied}; loss ${fixed(m.loss, 4)}`
      : `refused: ${m.message}`;
  } else {
    $('v-retune').textContent = m.state;
  }
}

// --- connection -------------------------------------------------------------------------------
function connect() {
  const ws = new WebSocket(`ws://${location.hostname}:${live.config.websocket_port}`, SUBPROTOCOLS);
  client = new FoxgloveClient({ ws });
  client.on('open', () => { live.connected = true; $('connection').textContent = 'connected'; $('connection').className = 'ok'; });
  client.on('close', () => {
    live.connected = false; $('connection').textContent = 'disconnected'; $('connection').className = 'bad';
    readers.clear(); topicOf.clear(); services.clear(); cmdChannel = null;
    setTimeout(connect, 1000);
  });
  client.on('error', (e) => keep(live.errors, String(e)));
  client.on('serverInfo', () => {
    cmdChannel = client.advertise({ topic: `${ns}/cmd_vel`, encoding: 'json', schemaName: 'geometry_msgs/msg/Twist' });
  });
  client.on('status', (s) => { if (/refused/.test(s.message)) keep(live.refusals, s.message); });
  client.on('advertise', (channels) => {
    for (const ch of channels) {
      const topic = rel(ch.topic);
      if (!WANTED.includes(topic)) continue;
      try {
        readers.set(ch.id, ch.encoding === 'json' ? 'json' : new MessageReader(parse(ch.schema, { ros2: true })));
      } catch (e) { keep(live.errors, `${topic}: ${e}`); continue; }
      topicOf.set(client.subscribe(ch.id), { topic, channel: ch.id });
    }
  });
  client.on('advertiseServices', (list) => { for (const s of list) services.set(s.name, s.id); });
  client.on('message', ({ subscriptionId, data }) => {
    const sub = topicOf.get(subscriptionId);
    if (!sub) return;
    const reader = readers.get(sub.channel);
    try {
      onMessage(sub.topic, reader === 'json' ? JSON.parse(new TextDecoder().decode(data)) : reader.readMessage(data));
    } catch (e) { keep(live.errors, `${sub.topic}: ${e}`); }
  });
  client.on('serviceCallResponse', ({ callId, data }) => {
    const call = calls.get(callId);
    if (call) { calls.delete(callId); call.resolve(JSON.parse(new TextDecoder().decode(data))); }
  });
  client.on('serviceCallFailure', ({ callId, message }) => {
    const call = calls.get(callId);
    if (call) { calls.delete(callId); call.reject(new Error(message)); }
  });
}

async function main() {
  live.config = await (await fetch('config.json')).json();
  ns = live.config.namespace;
  makePlots();
  wireControls();
  connect();
  setInterval(refresh, 100);
}

main();
