// Reads an MCAP file the way Foxglove's own libraries do and prints what it holds as one JSON object.
//
//   node read_mcap.mjs FILE.mcap
//
// The file is opened with @mcap/core's McapIndexedReader (so it needs a summary with chunk indexes, as
// graspsim's recordings have; @mcap/support supplies the zstd, lz4 and bz2 chunk decompressors, @mcap/nodejs the
// file-backed IReadable). Every message of every protobuf channel is decoded with protobufjs from the
// google.protobuf.FileDescriptorSet in its schema (protobufjs/ext/descriptor, Root.fromDescriptor). Output:
//   profile, library            the header's
//   messages                    messages read, every channel
//   per_topic                   {topic: messages}
//   schemas                     the schema names, sorted
//   channels                    [{topic, schema, schema_encoding, message_encoding, messages}]
//   compression                 {chunk compression ("" = none): chunks}
//   statistics_message_count    the summary's Statistics record (null without one)
//   decoded_all                 every message of every protobuf channel decoded (and every protobuf schema loaded)
//   undecodable                 the first few errors (topic, schema, what)
//   not_protobuf                {message encoding: messages} of channels that are not protobuf
//   reencoded_size_differs      {topic: messages} whose re-encoding has another size: a hint (not counted in
//                               decoded_all) that the data holds fields the schema lacks, i.e. another type
//   first_tf_child_ids          child_frame_id of each transform in the first foxglove.FrameTransforms message
// Exit code 0 when the file could be read (even if decoded_all is false); 1 when it could not (a message on
// stderr): not an MCAP file, no index, a bad CRC, a chunk that does not decompress.
import { open } from "node:fs/promises";
import { McapIndexedReader } from "@mcap/core";
import { FileHandleReadable } from "@mcap/nodejs";
import { loadDecompressHandlers } from "@mcap/support";

import { get, protobufType } from "./protobuf_schema.mjs";

const MAX_ERRORS = 10;

async function main() {
  const path = process.argv[2];
  if (!path) {
    process.stderr.write("usage: node read_mcap.mjs FILE.mcap\n");
    process.exit(1);
  }
  let handle;
  try {
    handle = await open(path, "r");
  } catch (error) {
    process.stderr.write(`read_mcap: cannot open ${path}: ${error.message}\n`);
    process.exit(1);
  }
  const out = {
    file: path,
    profile: null,
    library: null,
    messages: 0,
    per_topic: {},
    schemas: [],
    channels: [],
    compression: {},
    statistics_message_count: null,
    decoded_all: true,
    undecodable: [],
    not_protobuf: {},
    reencoded_size_differs: {},
    first_tf_child_ids: [],
  };
  let failures = 0;
  const fail = (topic, schema, what) => {
    out.decoded_all = false;
    failures += 1;
    if (out.undecodable.length < MAX_ERRORS) out.undecodable.push({ topic, schema, error: String(what) });
  };
  try {
    const reader = await McapIndexedReader.Initialize({
      readable: new FileHandleReadable(handle),
      decompressHandlers: await loadDecompressHandlers(),
    });
    out.profile = reader.header.profile;
    out.library = reader.header.library;
    if (reader.statistics) out.statistics_message_count = Number(reader.statistics.messageCount);
    for (const chunk of reader.chunkIndexes) {
      out.compression[chunk.compression] = (out.compression[chunk.compression] ?? 0) + 1;
    }
    out.schemas = [...new Set([...reader.schemasById.values()].map((s) => s.name))].sort();

    // Per channel: its topic, schema, and the protobufjs type (null when not protobuf or not loadable).
    const channels = new Map();
    const types = new Map();  // schema id -> Type | Error
    for (const channel of reader.channelsById.values()) {
      const schema = reader.schemasById.get(channel.schemaId);
      const info = {
        topic: channel.topic,
        schema: schema?.name ?? "",
        schema_encoding: schema?.encoding ?? "",
        message_encoding: channel.messageEncoding,
        messages: 0,
        type: null,
      };
      if (channel.messageEncoding === "protobuf") {
        if (!schema || schema.encoding !== "protobuf") {
          fail(channel.topic, info.schema, `protobuf channel with schema encoding '${info.schema_encoding}'`);
        } else {
          if (!types.has(schema.id)) {
            try {
              types.set(schema.id, protobufType(schema.name, schema.data));
            } catch (error) {
              types.set(schema.id, error);
              fail(channel.topic, schema.name, `schema does not load: ${error.message}`);
            }
          }
          const type = types.get(schema.id);
          info.type = type instanceof Error ? null : type;
        }
      }
      channels.set(channel.id, info);
    }

    let tfSeen = false;
    for await (const message of reader.readMessages()) {
      const info = channels.get(message.channelId);
      out.messages += 1;
      const topic = info ? info.topic : `<channel ${message.channelId}>`;
      out.per_topic[topic] = (out.per_topic[topic] ?? 0) + 1;
      if (!info) {
        fail(topic, "", "message on a channel the summary does not list");
        continue;
      }
      info.messages += 1;
      if (info.message_encoding !== "protobuf") {
        out.not_protobuf[info.message_encoding] = (out.not_protobuf[info.message_encoding] ?? 0) + 1;
        continue;
      }
      if (!info.type) {
        out.decoded_all = false;  // its schema did not load (reported once above)
        continue;
      }
      let decoded;
      try {
        decoded = info.type.decode(message.data);
      } catch (error) {
        fail(topic, info.schema, `message ${info.messages} (log time ${message.logTime} ns): ${error.message}`);
        continue;
      }
      if (info.type.encode(decoded).finish().length !== message.data.length) {
        out.reencoded_size_differs[topic] = (out.reencoded_size_differs[topic] ?? 0) + 1;
      }
      if (!tfSeen && info.schema === "foxglove.FrameTransforms") {
        tfSeen = true;
        const transforms = get(decoded, "transforms") ?? [];
        out.first_tf_child_ids = transforms.map((t) => get(t, "child_frame_id"));
      }
    }
    out.channels = [...channels.values()]
      .map(({ type, ...rest }) => rest)
      .sort((a, b) => (a.topic < b.topic ? -1 : a.topic > b.topic ? 1 : 0));
    if (failures > out.undecodable.length) out.undecodable_total = failures;
  } catch (error) {
    process.stderr.write(`read_mcap: cannot read ${path}: ${error.message ?? error}\n`);
    await handle.close();
    process.exit(1);
  }
  await handle.close();
  process.stdout.write(JSON.stringify(out) + "\n");
}

await main();
