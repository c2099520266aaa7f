// Decoding protobuf messages from the schema a recording or a live channel carries, shared by read_mcap.mjs and
// foxglove_live.mjs.
import protobuf from "protobufjs";
import descriptor from "protobufjs/ext/descriptor/index.js";

// The message type of a protobuf schema: `fileDescriptorSet` is a serialized FileDescriptorSet holding
// `schemaName`.
export function protobufType(schemaName, fileDescriptorSet) {
  const set = descriptor.FileDescriptorSet.decode(fileDescriptorSet);
  const root = protobuf.Root.fromDescriptor(set);
  return root.lookupType(schemaName.replace(/^\./, ""));
}

// A field of a decoded message by its .proto name (protobufjs keeps the snake_case names when built from a
// descriptor; camelCase is accepted too).
export function get(object, snake) {
  if (object == null) return undefined;
  if (snake in object) return object[snake];
  const camel = snake.replace(/_([a-z])/g, (_, c) => c.toUpperCase());
  return object[camel];
}
