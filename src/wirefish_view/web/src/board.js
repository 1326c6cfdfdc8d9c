// SPDX-License-Identifier: Apache-2.0
// The fish's link, gait and health as the bridge reports them in /diagnostics (its status
// `<namespace>/bridge_node: serial link <port>`, values as text): pure functions from those
// key-values to what the page shows. A value the bridge does not know ('nan', 'inf', 'none
// yet', or a key it did not send) is shown blank, never as NaN.

// Status bits of the fish's telemetry (wirefish_bridge.protocol.Status).
export const STATUS = {
  FAILSAFE_COMMAND: 0x0001, // stream mode: no command, slewing to / holding neutral
  FAILSAFE_HEARTBEAT: 0x0002, // stream mode: no host heartbeat, the same slew
  VERSION_MISMATCH: 0x0020, // stream mode: the host speaks another protocol, the same slew
  COASTING: 0x0040, // gait mode, link lost: still swimming the last gait
  RESTING: 0x0080, // gait mode, link lost past the coast time: tail brought to rest
  GAIT_MODE: 0x0100,
  CLOCK_FALLBACK: 0x0200,
};

// Clock sources that mean the crystal failed (the board runs on its RC oscillator).
const FALLBACK_CLOCKS = new Set(['HSI_PLL', 'HSI']);
// Telemetry older than this (s) and the bridge's last status bits no longer say the fish's
// state: 10 periods of the slowest telemetry the link config allows would be too lax, the
// default 10 ms period's 100 too strict on a loaded radio.
export const STALE_TELEMETRY_S = 1.0;

// The fish's drop counters (HEALTH) and the host's own, as labelled on the page.
export const COUNTERS = [
  ['fish_uart_rx_overruns', 'UART rx overruns'],
  ['fish_tx_bytes_dropped', 'tx bytes dropped'],
  ['fish_rx_crc', 'rx CRC errors'],
  ['fish_rx_frame', 'rx framing errors'],
  ['fish_rx_unknown_type', 'rx unknown type'],
  ['fish_rx_length', 'rx bad length'],
  ['fish_rx_invalid', 'rx invalid payload'],
  ['fish_imu_faults', 'IMU faults'],
  ['fish_imu_recoveries', 'IMU recoveries'],
  ['fish_i2c_bus_recoveries', 'I2C bus recoveries'],
  ['drops', 'host: sequence gaps'],
  ['frames_out_dropped', 'host: frames not sent'],
  ['fish_restarts', 'host: fish restarts seen'],
];

// Texts of values the bridge does not know. A board's own UNKNOWN (a reset cause it could not
// tell, as on QEMU) is what the board said: shown as such.
const UNKNOWN = new Set(['', 'nan', '-nan', 'inf', '-inf', 'none yet']);

// The text of a value, or '' when the bridge does not know it.
export function text(values, key) {
  const v = values[key];
  return v === undefined || UNKNOWN.has(String(v).trim().toLowerCase()) ? '' : String(v);
}

// A number of a value, or null when it is not a finite number.
export function number(values, key) {
  const t = text(values, key);
  const v = t === '' ? NaN : Number(t);
  return Number.isFinite(v) ? v : null;
}

// The status word of 'fish_status' ('0x0140 (COASTING, GAIT_MODE)'), or null.
export function statusWord(values) {
  const m = /^0x([0-9a-f]+)/i.exec(text(values, 'fish_status'));
  return m ? parseInt(m[1], 16) : null;
}

// Seconds as '1 h 02 min', '3 min 04 s' or '12.3 s'.
export function duration(s) {
  if (s === null) return '';
  if (s >= 3600) return `${Math.floor(s / 3600)} h ${String(Math.floor((s % 3600) / 60)).padStart(2, '0')} min`;
  if (s >= 60) return `${Math.floor(s / 60)} min ${String(Math.floor(s % 60)).padStart(2, '0')} s`;
  return `${s.toFixed(1)} s`;
}

/**
 * The link and gait state: {state, words, level} with state one of 'unknown', 'down',
 * 'silent', 'resting', 'coasting', 'gait', 'failsafe', 'stream'; words the badge's text;
 * level 'ok', 'warn' or 'bad' (the badge's colour).
 */
export function linkState(values) {
  if (!values) return { state: 'unknown', words: 'no report from the bridge yet', level: 'warn' };
  const link = text(values, 'link_state');
  if (link && link !== 'connected') {
    const why = link === 'identifying' ? 'the port is open, no fish heartbeat yet' : 'no fish on the line';
    return { state: 'down', words: `link ${link}: ${why}`, level: 'bad' };
  }
  const age = number(values, 'last_telemetry_age_s');
  const gaitMode = text(values, 'drive_mode') === 'gait';
  if (age === null || age > STALE_TELEMETRY_S) {
    const since = age === null ? 'no telemetry yet' : `no telemetry for ${age.toFixed(1)} s`;
    return { state: 'silent',
      words: `${since}: link lost${gaitMode ? ' (the fish coasts, then rests)' : ''}`,
      level: 'bad' };
  }
  const status = statusWord(values) ?? 0;
  if (status & STATUS.RESTING) {
    return { state: 'resting', words: 'resting: link lost, tail brought to rest', level: 'bad' };
  }
  if (status & STATUS.COASTING) {
    return { state: 'coasting', words: 'coasting: link lost, swimming the last gait', level: 'warn' };
  }
  if (status & STATUS.GAIT_MODE) {
    const id = text(values, 'board_gait_id');
    return { state: 'gait', words: `gait: the board swims gait ${id || '?'}`, level: 'ok' };
  }
  // Stream mode's failsafe: the targets move to neutral at a bounded rate (never a step).
  const why = [[STATUS.VERSION_MISMATCH, 'protocol version mismatch'],
    [STATUS.FAILSAFE_HEARTBEAT, 'no host heartbeat'], [STATUS.FAILSAFE_COMMAND, 'no command']]
    .filter(([bit]) => status & bit).map(([, words]) => words);
  if (why.length) {
    return { state: 'failsafe', words: `failsafe: ${why.join(', ')}, tail slewing to neutral`, level: 'warn' };
  }
  return { state: 'stream', words: 'stream: the host commands the servos', level: 'ok' };
}

// The reset cause, with where the fault was when the board kept a fault record.
export function resetCause(values) {
  const cause = text(values, 'fish_reset_cause');
  const pc = text(values, 'fish_fault_pc');
  if (!cause || !pc) return cause;
  const more = ['fish_fault_lr', 'fish_fault_cfsr', 'fish_fault_hfsr']
    .filter((k) => text(values, k)).map((k) => `${k.slice(11).toUpperCase()} ${text(values, k)}`);
  return `${cause} at PC ${pc}${more.length ? ` (${more.join(', ')})` : ''}`;
}

// The clock source and whether it is the fallback (crystal failed).
export function clock(values) {
  const source = text(values, 'fish_clock');
  const status = statusWord(values) ?? 0;
  const fallback = FALLBACK_CLOCKS.has(source) || Boolean(status & STATUS.CLOCK_FALLBACK);
  return { source, fallback, words: fallback ? `${source || 'HSI'}: fallback, the crystal failed` : source };
}

// What the page shows of the board's health.
export function health(values) {
  const v = values || {};
  // A board that does not measure its stack (the virtual fish) reports a size of 0.
  const stack = /^(\d+) of ([1-9]\d*)/.exec(text(v, 'fish_stack_free_min'));
  return {
    reset_cause: resetCause(v),
    uptime: duration(number(v, 'fish_uptime_s')),
    clock: clock(v),
    stack: stack ? `${stack[1]} of ${stack[2]} bytes never used` : '',
    flags: text(v, 'fish_health_flags'),
    counters: COUNTERS.map(([key, label]) => ({ key, label, value: text(v, key) })),
  };
}

// The largest rate (rad/s) either servo moved at between the oldest and newest of `samples`
// ({t, position}), or null with fewer than two samples or no time between them.
export function observedRate(samples) {
  if (samples.length < 2) return null;
  const a = samples[0]; const b = samples[samples.length - 1];
  const dt = b.t - a.t;
  if (!(dt > 0)) return null;
  return Math.max(...a.position.map((p, i) => Math.abs(b.position[i] - p) / dt));
}
