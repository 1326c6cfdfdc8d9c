// SPDX-License-Identifier: Apache-2.0
// Foxglove's own client library against the view: @foxglove/ws-protocol's FoxgloveClient on a
// WebSocket that offers the client's default subprotocol (FoxgloveClient.SUPPORTED_SUBPROTOCOL),
// every advertised channel subscribed, each message decoded as a viewer does (CDR with
// @foxglove/rosmsg2-serialization from the channel's ros2msg schema, JSON, protobuf's wire
// format), counted over a window of the messages' own time (their header stamps: simulated
// time when the graph runs on it) and of wall time.
//
//   node --experimental-websocket ws_protocol_client.js URL WARMUP_S WINDOW_S WALL_LIMIT_S REF OUT
//
// After WARMUP_S of wall time the window opens at the latest stamp of topic REF; the client stops
// once REF's stamps have advanced WINDOW_S + 1 past it (or after WALL_LIMIT_S). Writes {subprotocol,
// start, windowS, wallS, channels: {topic: {encoding, schemaName, stamps, wallCount, received,
// failures, firstError, sample}}, statuses} to OUT: stamps are those (s) of the messages
// received after the warm-up, wallCount the messages received in the wall window.
'use strict';
const path = require('path');

const web = path.resolve(__dirname, '../../src/wirefish_view/web/node_modules');
const { FoxgloveClient } = require(path.join(web, '@foxglove/ws-protocol'));
const { parse } = require(path.join(web, '@foxglove/rosmsg'));
const { MessageReader } = require(path.join(web, '@foxglove/rosmsg2-serialization'));
const fs = require('fs');

const [url, warmupS, windowS, wallLimitS, reference, out] = process.argv.slice(2);

// A protobuf message's wire format, walked field by field to its end: a decode that checks
// every tag, varint and length (the schema's FileDescriptorSet would need protobufjs).
function walkProtobuf(bytes) {
  let i = 0;
  const fields = new Set();
  const varint = () => {
    let value = 0; let shift = 0;
    for (;;) {
      if (i >= bytes.length) throw new Error('truncated varint');
      const b = bytes[i++];
      value += (b & 0x7f) * 2 ** shift;
      shift += 7;
      if (!(b & 0x80)) return value;
      if (shift > 63) throw new Error('varint too long');
    }
  };
  while (i < bytes.length) {
    const tag = varint();
    const wire = tag & 7;
    fields.add(Math.floor(tag / 8));
    if (wire === 0) varint();
    else if (wire === 1) i += 8;
    else if (wire === 2) { const length = varint(); i += length; }
    else if (wire === 5) i += 4;
    else throw new Error(`wire type ${wire}`);
    if (i > bytes.length) throw new Error('field past the end');
  }
  return { fields: [...fields] };
}

function decoderOf(channel) {
  if (channel.encoding === 'cdr' && channel.schemaEncoding === 'ros2msg') {
    const reader = new MessageReader(parse(channel.schema, { ros2: true }));
    return (data) => reader.readMessage(data);
  }
  if (channel.encoding === 'json') return (data) => JSON.parse(new TextDecoder().decode(data));
  if (channel.encoding === 'protobuf') return (data) => walkProtobuf(data);
  return () => { throw new Error(`no decoder for ${channel.encoding}`); };
}

const ws = new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
const client = new FoxgloveClient({ ws });
const channels = {}; // topic -> result
const bySubscription = new Map();
const statuses = [];
let warm = false;
let latestStamp = -Infinity;
let start = null;
let wallStart = null;

// A message's own time (s): its header's, a TF message's first transform's, a marker array's
// first marker's; null for a message without one.
function stampOf(m) {
  const header = m && (m.header || (m.transforms && m.transforms[0] && m.transforms[0].header)
    || (m.markers && m.markers[0] && m.markers[0].header));
  if (!header || !header.stamp) return null;
  return header.stamp.sec + header.stamp.nanosec * 1e-9;
}

// /diagnostics is shared by every graph of the ROS domain: a status array none of whose names
// is in REF's namespace is another graph's (counted as foreign, not in stamps).
const namespace = reference.slice(0, reference.lastIndexOf('/'));
function foreign(m) {
  return Array.isArray(m && m.status) && m.status.length > 0
    && !m.status.some((s) => s.name.startsWith(`${namespace}/`));
}

function finish(code, extra) {
  fs.writeFileSync(out, JSON.stringify({ subprotocol: ws.protocol, start, windowS: Number(windowS),
    wallS: wallStart === null ? 0 : (Date.now() - wallStart) / 1000, channels, statuses,
    ...extra }));
  client.close();
  process.exit(code);
}

client.on('advertise', (list) => {
  for (const channel of list) {
    if (channels[channel.topic]) continue;
    let decode;
    const result = { reference: channel.topic === reference, encoding: channel.encoding, schemaName: channel.schemaName, stamps: [],
      wallCount: 0, foreign: 0, received: 0, failures: 0, firstError: null, sample: null };
    try { decode = decoderOf(channel); } catch (e) {
      result.failures += 1; result.firstError = `schema: ${e}`; decode = null;
    }
    channels[channel.topic] = result;
    if (decode) bySubscription.set(client.subscribe(channel.id), { result, decode });
  }
});
client.on('status', (s) => statuses.push(s.message));
client.on('message', ({ subscriptionId, data }) => {
  const sub = bySubscription.get(subscriptionId);
  if (!sub) return;
  sub.result.received += 1;
  let message;
  try {
    message = sub.decode(new Uint8Array(data.buffer, data.byteOffset, data.byteLength));
  } catch (e) {
    sub.result.failures += 1;
    if (!sub.result.firstError) sub.result.firstError = String(e);
    return;
  }
  const stamp = stampOf(message);
  if (sub.result.reference && stamp !== null && stamp > latestStamp) latestStamp = stamp;
  if (warm && foreign(message)) {
    sub.result.foreign += 1;
  } else if (warm) {
    sub.result.wallCount += 1;
    if (stamp !== null) sub.result.stamps.push(stamp);
    if (start !== null && latestStamp >= start + Number(windowS) + 1) finish(0, {});
  }
  if (!sub.result.sample) {
    sub.result.sample = JSON.stringify(message, (_k, v) => (typeof v === 'bigint' ? String(v)
      : (ArrayBuffer.isView(v) ? Array.from(v) : v))).slice(0, 300);
  }
});
client.on('error', (e) => statuses.push(`error: ${e && e.message ? e.message : e}`));
client.on('open', () => {
  setTimeout(() => {
    warm = true;
    wallStart = Date.now();
    start = latestStamp;
  }, 1000 * Number(warmupS));
  setTimeout(() => finish(4, { timedOut: true }), 1000 * Number(wallLimitS));
});
client.on('close', (event) => finish(3, { closed: String(event && (event.reason || event.code)) }));
