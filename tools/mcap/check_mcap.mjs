#!/usr/bin/env node
// Checks an MCAP file that write_mcap.mjs wrote, as Foxglove Studio would
// read it:
//   - it has a summary (McapIndexedReader: chunk indexes, statistics);
//   - every channel's message encoding is "json" and its schema's encoding
//     "jsonschema", and the schema compiles with ajv;
//   - every message is UTF-8 JSON that its channel's schema accepts;
//   - the statistics (message count, per channel, start and end time,
//     channel, schema and chunk counts) agree with the messages read, and a
//     plain front-to-back read (McapStreamReader) finds the same messages.
//
//   node check_mcap.mjs FILE.mcap
//
// Prints one JSON line on stdout:
//   {"messages": N, "channels": {"RMS_DCP_FRAME": n, ...}, "schemas": ["rms.dcp_frame_t", ...], "invalid": 0}
// and exits 0 only when every check passes and N > 0. Otherwise the line also
// has "first_invalid" ({channel, index (the message's place on its channel,
// from 0), log_time_ns, error}) and/or "errors" (what else failed), the same
// is said on stderr, and the exit status is 1.
import { createReadStream } from "node:fs";
import { open } from "node:fs/promises";

import Ajv from "ajv";
import { McapIndexedReader, McapStreamReader } from "@mcap/core";

// McapIndexedReader's input: a file, read at any offset.
class FileReadable {
  constructor(handle, size) {
    this.handle = handle;
    this.bytes = size;
  }
  async size() {
    return BigInt(this.bytes);
  }
  async read(offset, size) {
    if (offset + size > BigInt(this.bytes)) {
      throw new Error(`read past the end of the file (${offset} + ${size} > ${this.bytes})`);
    }
    const buffer = Buffer.alloc(Number(size));
    let done = 0;
    while (done < buffer.length) {
      const { bytesRead } = await this.handle.read(buffer, done, buffer.length - done, Number(offset) + done);
      if (bytesRead === 0) throw new Error(`short read at ${Number(offset) + done}`);
      done += bytesRead;
    }
    return buffer;
  }
}

function ajvError(errors) {
  return (errors ?? [])
    .slice(0, 3)
    .map((e) => `${e.instancePath || "(the message)"} ${e.message}${e.params && Object.keys(e.params).length ? " " + JSON.stringify(e.params) : ""}`)
    .join("; ");
}

// A front-to-back read of the whole file: the messages per channel id, in
// file order, as a reader with no index sees them.
async function streamCounts(file) {
  const reader = new McapStreamReader();
  const counts = new Map();
  for await (const chunk of createReadStream(file, { highWaterMark: 1 << 20 })) {
    reader.append(chunk);
    for (let record; (record = reader.nextRecord()); ) {
      if (record.type === "Message") counts.set(record.channelId, (counts.get(record.channelId) ?? 0) + 1);
    }
  }
  if (!reader.done()) throw new Error("the file ends before its footer (truncated?)");
  return counts;
}

async function main() {
  const file = process.argv[2];
  if (!file || process.argv.length !== 3 || file === "--help" || file === "-h") {
    console.error("usage: node check_mcap.mjs FILE.mcap");
    return 2;
  }
  const errors = [];
  const result = { messages: 0, channels: {}, schemas: [], invalid: 0 };
  const finish = (firstInvalid) => {
    if (firstInvalid) result.first_invalid = firstInvalid;
    if (result.messages === 0 && errors.length === 0) errors.push("no messages");
    if (errors.length) result.errors = errors;
    console.log(JSON.stringify(result));
    if (firstInvalid) {
      console.error(
        `check_mcap: ${result.invalid} invalid message(s); the first: channel ${firstInvalid.channel}, ` +
          `index ${firstInvalid.index} (log time ${firstInvalid.log_time_ns} ns): ${firstInvalid.error}`,
      );
    }
    for (const e of errors) console.error(`check_mcap: ${e}`);
    return firstInvalid || errors.length ? 1 : 0;
  };

  let handle;
  try {
    handle = await open(file, "r");
  } catch (e) {
    errors.push(`cannot open ${file}: ${e.message}`);
    return finish();
  }
  try {
    const { size } = await handle.stat();
    let reader;
    try {
      reader = await McapIndexedReader.Initialize({ readable: new FileReadable(handle, size) });
    } catch (e) {
      errors.push(`not an indexed MCAP file (no summary?): ${e.message}`);
      return finish();
    }

    // Schemas and channels.
    const ajv = new Ajv({ allErrors: false, strict: true });
    const validators = new Map(); // schema id -> validate function
    const channelName = new Map(); // channel id -> topic
    const perChannel = new Map(); // channel id -> messages read
    for (const schema of reader.schemasById.values()) {
      result.schemas.push(schema.name);
      if (schema.encoding !== "jsonschema") {
        errors.push(`schema ${schema.name}: encoding "${schema.encoding}", not "jsonschema"`);
        continue;
      }
      try {
        const parsed = JSON.parse(new TextDecoder("utf-8", { fatal: true }).decode(schema.data));
        validators.set(schema.id, ajv.compile(parsed));
      } catch (e) {
        errors.push(`schema ${schema.name}: does not compile: ${e.message}`);
      }
    }
    result.schemas.sort();
    for (const ch of reader.channelsById.values()) {
      channelName.set(ch.id, ch.topic);
      perChannel.set(ch.id, 0);
      result.channels[ch.topic] = 0;
      if (ch.messageEncoding !== "json") errors.push(`channel ${ch.topic}: message encoding "${ch.messageEncoding}", not "json"`);
      if (!reader.schemasById.has(ch.schemaId)) errors.push(`channel ${ch.topic}: no schema (id ${ch.schemaId})`);
    }

    // Every message.
    const decoder = new TextDecoder("utf-8", { fatal: true });
    let firstInvalid;
    let start;
    let end;
    try {
      for await (const msg of reader.readMessages()) {
        const index = perChannel.get(msg.channelId);
        if (index === undefined) {
          errors.push(`a message on channel id ${msg.channelId}, which the file does not define`);
          break;
        }
        perChannel.set(msg.channelId, index + 1);
        result.messages++;
        if (start === undefined || msg.logTime < start) start = msg.logTime;
        if (end === undefined || msg.logTime > end) end = msg.logTime;
        const validate = validators.get(reader.channelsById.get(msg.channelId).schemaId);
        let error;
        try {
          const value = JSON.parse(decoder.decode(msg.data));
          if (validate && !validate(value)) error = ajvError(validate.errors);
        } catch (e) {
          error = `not UTF-8 JSON: ${e.message}`;
        }
        if (error !== undefined) {
          result.invalid++;
          firstInvalid ??= { channel: channelName.get(msg.channelId), index, log_time_ns: String(msg.logTime), error };
        }
      }
    } catch (e) {
      errors.push(`reading the messages failed after ${result.messages}: ${e.message}`);
    }
    for (const [id, n] of perChannel) result.channels[channelName.get(id)] = n;

    // The summary against what was read.
    const stats = reader.statistics;
    if (!stats) {
      errors.push("no statistics record in the summary");
    } else {
      if (stats.messageCount !== BigInt(result.messages)) {
        errors.push(`statistics: ${stats.messageCount} messages, ${result.messages} read`);
      }
      for (const [id, n] of perChannel) {
        const s = stats.channelMessageCounts.get(id) ?? 0n;
        if (s !== BigInt(n)) errors.push(`statistics: channel ${channelName.get(id)}: ${s} messages, ${n} read`);
      }
      for (const id of stats.channelMessageCounts.keys()) {
        if (!perChannel.has(id)) errors.push(`statistics: counts for channel id ${id}, which the file does not define`);
      }
      if (result.messages > 0 && (stats.messageStartTime !== start || stats.messageEndTime !== end)) {
        errors.push(`statistics: time ${stats.messageStartTime}..${stats.messageEndTime} ns, messages ${start}..${end} ns`);
      }
      if (stats.channelCount !== reader.channelsById.size) {
        errors.push(`statistics: ${stats.channelCount} channels, ${reader.channelsById.size} in the summary`);
      }
      if (stats.schemaCount !== reader.schemasById.size) {
        errors.push(`statistics: ${stats.schemaCount} schemas, ${reader.schemasById.size} in the summary`);
      }
      if (stats.chunkCount !== reader.chunkIndexes.length) {
        errors.push(`statistics: ${stats.chunkCount} chunks, ${reader.chunkIndexes.length} chunk indexes`);
      }
    }
    try {
      const streamed = await streamCounts(file);
      for (const id of new Set([...streamed.keys(), ...perChannel.keys()])) {
        const a = streamed.get(id) ?? 0;
        const b = perChannel.get(id) ?? 0;
        if (a !== b) {
          errors.push(`channel ${channelName.get(id) ?? `id ${id}`}: ${a} messages front to back, ${b} through the index`);
        }
      }
    } catch (e) {
      errors.push(`front-to-back read failed: ${e.message}`);
    }
    return finish(firstInvalid);
  } finally {
    await handle.close();
  }
}

process.exitCode = await main();
