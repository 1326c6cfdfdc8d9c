// Foxglove's own client library against the view: @foxglove/ws-protocol's FoxgloveClient on a
// WebSocket that offers the client's default subprotocol (FoxgloveClient.SUPPORTED_SUBPROTOCOL),
// every advertised channel subscribed, each message decoded as a viewer does (CDR with
// @foxglove/rosmsg2-serialization from the channel's ros2msg schema, JSON, protobuf's wire
// format), counted over a window.
//
//   node --experimental-websocket ws_protocol_client.js URL WARMUP_S WINDOW_S OUT.json
//
// Writes {subprotocol, channels: {topic: {encoding, schemaName, count, failures, firstError,
// sample}}, statuses} to OUT.json; count is the messages received within the window.
'use strict';
const path = require('path');

const web = path.resolve(__dirname, '../../src/wirefish_view/web/node_modules');
const { FoxgloveClient } = require(path.join(web, '@foxglove/ws-protocol'));
const { parse } = require(path.join(web, '@foxglove/rosmsg'));
const { MessageReader } = require(path.join(web, '@foxglove/rosmsg2-serialization'));
const fs = require('fs');

const [url, warmupS, windowS, out] = process.argv.slice(2);

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
let windowStart = null;
let windowEnd = null;

client.on('advertise', (list) => {
  for (const channel of list) {
    if (channels[channel.topic]) continue;
    let decode;
    const result = { encoding: channel.encoding, schemaName: channel.schemaName, count: 0,
      received: 0, failures: 0, firstError: null, sample: null };
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
  const now = Date.now();
  sub.result.received += 1;
  let message;
  try {
    message = sub.decode(new Uint8Array(data.buffer, data.byteOffset, data.byteLength));
  } catch (e) {
    sub.result.failures += 1;
    if (!sub.result.firstError) sub.result.firstError = String(e);
    return;
  }
  if (windowStart !== null && now >= windowStart && now < windowEnd) sub.result.count += 1;
  if (!sub.result.sample) {
    sub.result.sample = JSON.stringify(message, (_k, v) => (typeof v === 'bigint' ? String(v)
      : (ArrayBuffer.isView(v) ? Array.from(v) : v))).slice(0, 300);
  }
});
client.on('error', (e) => statuses.push(`error: ${e && e.message ? e.message : e}`));
client.on('open', () => {
  windowStart = Date.now() + 1000 * Number(warmupS);
  windowEnd = windowStart + 1000 * Number(windowS);
  setTimeout(() => {
    fs.writeFileSync(out, JSON.stringify({ subprotocol: ws.protocol, windowS: Number(windowS),
      channels, statuses }, null, 1));
    client.close();
    process.exit(0);
  }, windowEnd - Date.now() + 200);
});
client.on('close', (event) => {
  if (windowEnd === null || Date.now() < windowEnd) {
    fs.writeFileSync(out, JSON.stringify({ subprotocol: ws.protocol, closed: String(
      event && (event.reason || event.code)), channels, statuses }));
    process.exit(3);
  }
});
