// Subscribes to one topic of a Foxglove WebSocket server the way Foxglove's own client library does and prints
// what came as one JSON object.
//
//   node foxglove_live.mjs WS_URL TOPIC COUNT [TIMEOUT_S] [--subprotocol=NAME]
//   e.g. node foxglove_live.mjs ws://127.0.0.1:8765/<scene id> /tf 5 10
//
// Connects with @foxglove/ws-protocol's FoxgloveClient over the `ws` package, offering only the subprotocol
// foxglove.websocket.v1 (what the Foxglove app speaks; --subprotocol=NAME offers NAME instead, e.g.
// foxglove.sdk.v1, the only one the Python foxglove-sdk 0.30 server accepts),
// waits for serverInfo and the advertisement of TOPIC, subscribes to that channel and decodes each message with
// protobufjs from the channel's schema (a base64 google.protobuf.FileDescriptorSet, schemaEncoding "protobuf").
// Prints, after COUNT messages or TIMEOUT_S seconds (default 10):
//   subprotocol                 the one the server chose
//   server_name, capabilities   from serverInfo
//   channels                    the advertised topics, in order of advertisement
//   schema_name                 TOPIC's schema ("" until advertised)
//   received                    messages of TOPIC received
//   decoded                     of them, decoded with the advertised schema
//   undecodable                 the first few errors (schema loading or message decoding)
//   first_child_ids             child_frame_id of each transform of the first foxglove.FrameTransforms message
//   first_log_time_ns           the first message's timestamp (ns, as a string)
//   statuses                    status messages: [{level, message}]
//   error                       why the connection failed or closed early (absent otherwise)
// Exit code 0 when COUNT messages came, 2 on the timeout (JSON still printed), 1 when the connection failed or
// the server closed it first (JSON printed, the reason also on stderr), 3 on bad arguments.
import wsProtocol from "@foxglove/ws-protocol";  // CommonJS for Node: no named exports
import WebSocket from "ws";

import { get, protobufType } from "./protobuf_schema.mjs";

const { FoxgloveClient } = wsProtocol;
const MAX_ERRORS = 10;

const args = process.argv.slice(2);
const subprotocols = args.filter((a) => a.startsWith("--subprotocol=")).map((a) => a.slice("--subprotocol=".length));
const [url, topic, countText, timeoutText] = args.filter((a) => !a.startsWith("--subprotocol="));
const count = Number(countText);
const timeoutS = timeoutText === undefined ? 10 : Number(timeoutText);
if (!url || !topic || !Number.isInteger(count) || count < 1 || !(timeoutS > 0)) {
  process.stderr.write("usage: node foxglove_live.mjs WS_URL TOPIC COUNT [TIMEOUT_S] [--subprotocol=NAME]\n");
  process.exit(3);
}

const out = {
  url,
  topic,
  subprotocol: null,
  server_name: null,
  capabilities: [],
  channels: [],
  schema_name: "",
  received: 0,
  decoded: 0,
  undecodable: [],
  first_child_ids: [],
  first_log_time_ns: null,
  statuses: [],
};
const started = Date.now();
let finished = false;
let serverInfo = false;
let channel = null;      // the advertised channel of TOPIC
let type = null;         // its protobufjs type
let subscription = null; // our subscription id

const ws = new WebSocket(url, subprotocols.length ? subprotocols : [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
const client = new FoxgloveClient({ ws });

function finish(code, error) {
  if (finished) return;
  finished = true;
  clearTimeout(timer);
  if (error) {
    out.error = error;
    process.stderr.write(`foxglove_live: ${error}\n`);
  }
  out.elapsed_s = (Date.now() - started) / 1000;
  process.stdout.write(JSON.stringify(out) + "\n", () => {
    try {
      client.close();
    } catch {
      // already closed
    }
    process.exit(code);
  });
}

const timer = setTimeout(() => finish(2), timeoutS * 1000);

function fail(what) {
  if (out.undecodable.length < MAX_ERRORS) out.undecodable.push(String(what));
}

function maybeSubscribe() {
  if (!serverInfo || !channel || subscription !== null) return;
  const schemaEncoding = channel.schemaEncoding ?? (channel.encoding === "protobuf" ? "protobuf" : "");
  if (channel.encoding !== "protobuf" || schemaEncoding !== "protobuf") {
    fail(`channel ${topic}: encoding '${channel.encoding}', schema encoding '${schemaEncoding}', not protobuf`);
  } else {
    try {
      type = protobufType(channel.schemaName, Buffer.from(channel.schema, "base64"));
    } catch (error) {
      fail(`channel ${topic}: schema ${channel.schemaName} does not load: ${error.message}`);
    }
  }
  subscription = client.subscribe(channel.id);
}

client.on("open", () => {
  out.subprotocol = ws.protocol;
});
client.on("error", (error) => finish(1, `connection error: ${error?.message ?? error}`));
client.on("close", (event) => {
  if (!finished) finish(1, `the server closed the connection (code ${event?.code}${event?.reason ? `, ${event.reason}` : ""})`);
});
client.on("serverInfo", (info) => {
  out.server_name = info.name;
  out.capabilities = info.capabilities ?? [];
  serverInfo = true;
  maybeSubscribe();
});
client.on("status", (status) => {
  out.statuses.push({ level: status.level, message: status.message });
});
client.on("advertise", (channels) => {
  for (const advertised of channels) {
    out.channels.push(advertised.topic);
    if (advertised.topic === topic && channel === null) {
      channel = advertised;
      out.schema_name = advertised.schemaName;
    }
  }
  maybeSubscribe();
});
client.on("unadvertise", (ids) => {
  if (channel && ids.includes(channel.id)) fail(`channel ${topic} was unadvertised`);
});
client.on("message", (message) => {
  if (finished || message.subscriptionId !== subscription) return;
  out.received += 1;
  if (out.first_log_time_ns === null) out.first_log_time_ns = String(message.timestamp);
  if (type) {
    const bytes = new Uint8Array(message.data.buffer, message.data.byteOffset, message.data.byteLength);
    try {
      const decoded = type.decode(bytes);
      out.decoded += 1;
      if (out.decoded === 1 && channel.schemaName === "foxglove.FrameTransforms") {
        out.first_child_ids = (get(decoded, "transforms") ?? []).map((t) => get(t, "child_frame_id"));
      }
    } catch (error) {
      fail(`message ${out.received}: ${error.message}`);
    }
  }
  if (out.received >= count) finish(0);
});
