// Independent check of a mixpilot recording with the reference MCAP implementation
// (@mcap/core) and Foxglove's ROS 2 message parser and CDR deserializer.
//
//   node check.mjs <file.mcap> [--all TOPIC]...
//
// Prints one JSON object (see summarize() below) on stdout and exits 0, or prints
// {"error": "..."} and exits 1. tests/test_mcap_independent.cpp compares the output with what
// it wrote. Installed by `npm ci` (the CTest fixture mcap_check_npm_ci).
import { readFile } from "node:fs/promises";

import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import { crc32 } from "@foxglove/crc";
import { parse as parseMessageDefinition } from "@foxglove/rosmsg";
import { MessageReader } from "@foxglove/rosmsg2-serialization";

// JSON.stringify cannot print BigInt (uint64 fields) or typed arrays (float32[]/float64[]).
function plain(_key, value) {
  if (typeof value === "bigint") return Number(value);
  if (ArrayBuffer.isView(value)) return Array.from(value, (v) => (typeof v === "bigint" ? Number(v) : v));
  return value;
}

// `all`: topics whose every message the summary lists (under "all", in log-time order, each
// with its log time), not only the last one.
async function summarize(path, all) {
  const bytes = new Uint8Array(await readFile(path));

  // 1. Indexed reader: footer, summary CRC, Summary/Statistics/MetadataIndex records.
  const indexed = await McapIndexedReader.Initialize({
    readable: {
      size: async () => BigInt(bytes.byteLength),
      read: async (offset, length) => bytes.subarray(Number(offset), Number(offset + length)),
    },
  });
  const dataEnd = Number(indexed.dataEndOffset);
  let dataSectionCrc = "absent";
  if (indexed.dataSectionCrc !== undefined) {
    // The data section CRC covers every byte before the Data End record, leading magic included.
    dataSectionCrc = crc32(bytes.subarray(0, dataEnd)) === indexed.dataSectionCrc ? "ok" : "mismatch";
  }
  const metadata = [];
  for await (const m of indexed.readMetadata()) {
    metadata.push({ name: m.name, keys: [...m.metadata.keys()].sort() });
  }
  const stats = indexed.statistics;

  // 2. Stream reader: every record in file order; decode every message with its schema.
  const stream = new McapStreamReader({ validateCrcs: true });
  stream.append(bytes);
  const schemas = new Map();
  const channels = new Map();
  const readers = new Map();
  const counts = new Map();
  const last = {};
  const every = {};
  for (const topic of all) every[topic] = [];
  let header;
  let previousLogTime = -1n;
  for (let record; (record = stream.nextRecord()); ) {
    if (record.type === "Header") {
      header = record;
    } else if (record.type === "Schema") {
      schemas.set(record.id, record);
    } else if (record.type === "Channel") {
      if (!channels.has(record.id)) channels.set(record.id, record);
    } else if (record.type === "Message") {
      if (record.logTime < previousLogTime) throw new Error("messages out of log-time order");
      previousLogTime = record.logTime;
      const channel = channels.get(record.channelId);
      let reader = readers.get(channel.id);
      if (!reader) {
        const schema = schemas.get(channel.schemaId);
        const text = new TextDecoder().decode(schema.data);
        reader = new MessageReader(parseMessageDefinition(text, { ros2: true }));
        readers.set(channel.id, reader);
      }
      const message = reader.readMessage(record.data);
      counts.set(channel.topic, (counts.get(channel.topic) ?? 0) + 1);
      last[channel.topic] = message;
      if (every[channel.topic]) every[channel.topic].push({ logTime: record.logTime, message });
    }
  }
  if (!stream.done()) throw new Error("stream reader did not reach the footer and trailing magic");

  const channelList = [...channels.values()]
    .map((c) => {
      const s = schemas.get(c.schemaId);
      return {
        topic: c.topic,
        schemaName: s.name,
        schemaEncoding: s.encoding,
        messageEncoding: c.messageEncoding,
        messages: counts.get(c.topic) ?? 0,
        statistics: Number(stats.channelMessageCounts.get(c.id) ?? -1n),
      };
    })
    .sort((a, b) => (a.topic < b.topic ? -1 : a.topic > b.topic ? 1 : 0));
  const lastSorted = {};
  for (const topic of Object.keys(last).sort()) lastSorted[topic] = last[topic];

  const summary = {
    profile: header.profile,
    library: header.library,
    dataSectionCrc,
    statistics: {
      messageCount: Number(stats.messageCount),
      schemaCount: stats.schemaCount,
      channelCount: stats.channelCount,
      metadataCount: stats.metadataCount,
      messageStartTime: Number(stats.messageStartTime),
      messageEndTime: Number(stats.messageEndTime),
    },
    channels: channelList,
    metadata,
    last: lastSorted,
  };
  if (all.length > 0) summary.all = every;
  return summary;
}

try {
  let [path, ...options] = process.argv.slice(2);
  const all = [];
  for (let i = 0; i < options.length; i += 2) {
    if (options[i] !== "--all" || options[i + 1] === undefined) path = undefined;
    else all.push(options[i + 1]);
  }
  if (!path) throw new Error("usage: node check.mjs <file.mcap> [--all TOPIC]...");
  process.stdout.write(JSON.stringify(await summarize(path, all), plain) + "\n");
} catch (error) {
  process.stdout.write(JSON.stringify({ error: String(error?.message ?? error) }) + "\n");
  process.exitCode = 1;
}
