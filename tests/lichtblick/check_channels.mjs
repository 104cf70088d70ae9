// Opens an MCAP file as Foxglove Studio 1.48 does and prints, as one JSON document, what its
// parseChannel makes of every channel: the error it throws, or the datatypes (message
// definitions) that panels address fields by, and how many of the channel's messages the
// returned deserializer read.
//
//   node vendor/check_channels.mjs RECORDING.mcap
//
// Exit status: 0 when the JSON was printed (whatever it says), 2 when the file could not be read.
import { readFileSync } from "node:fs";

import { McapStreamReader } from "@mcap/core";
import { decompress } from "fzstd";

import { parseChannel } from "./build/parseChannel.mjs";

const PARSER = "@foxglove/studio-base@1.48.0 parseChannel";

const decompressHandlers = {
  zstd: (buffer, decompressedSize) => decompress(buffer, new Uint8Array(Number(decompressedSize))),
};

function errorText(error) {
  return error instanceof Error ? `${error.name}: ${error.message}` : String(error);
}

/** Every record of the file, chunks decompressed and CRCs checked. */
function* records(bytes) {
  const reader = new McapStreamReader({ decompressHandlers });
  reader.append(bytes);
  for (let record; (record = reader.nextRecord()); ) {
    yield record;
  }
  if (!reader.done()) {
    throw new Error(`the file ends inside a record (${reader.bytesRemaining()} bytes left)`);
  }
}

function checkChannels(path) {
  const schemas = new Map();
  const channels = new Map();
  for (const record of records(readFileSync(path))) {
    if (record.type === "Schema") {
      schemas.set(record.id, record);
    } else if (record.type === "Channel" && !channels.has(record.id)) {
      const schema = schemas.get(record.schemaId);
      const report = {
        id: record.id,
        topic: record.topic,
        message_encoding: record.messageEncoding,
        schema: schema?.name ?? null,
        schema_encoding: schema?.encoding ?? null,
        ok: true,
        error: null,
        messages: 0,
        failed_messages: 0,
        datatypes: null,
      };
      let parsed;
      try {
        // As McapIndexedIterableSource does: no schema record is an undefined schema.
        parsed = parseChannel({
          messageEncoding: record.messageEncoding,
          schema:
            schema == undefined
              ? undefined
              : { name: schema.name, encoding: schema.encoding, data: schema.data },
        });
        report.datatypes = Object.fromEntries(parsed.datatypes);
      } catch (error) {
        report.ok = false;
        report.error = errorText(error);
      }
      channels.set(record.id, { report, parsed });
    } else if (record.type === "Message") {
      const channel = channels.get(record.channelId);
      if (channel?.parsed == undefined) {
        continue; // Studio skips the messages of a channel it could not parse
      }
      try {
        channel.parsed.deserialize(record.data);
        channel.report.messages += 1;
      } catch (error) {
        channel.report.failed_messages += 1;
        if (channel.report.ok) {
          channel.report.ok = false;
          channel.report.error = `message at log_time ${record.logTime}: ${errorText(error)}`;
        }
      }
    }
  }
  return { file: path, parser: PARSER, channels: [...channels.values()].map((c) => c.report) };
}

const paths = process.argv.slice(2);
if (paths.length !== 1) {
  console.error("usage: node check_channels.mjs RECORDING.mcap");
  process.exit(2);
}
try {
  console.log(JSON.stringify(checkChannels(paths[0])));
} catch (error) {
  console.error(`${paths[0]}: ${errorText(error)}`);
  process.exit(2);
}
