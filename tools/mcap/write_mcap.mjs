#!/usr/bin/env node
// Writes a session's LCM log, given as JSON lines on stdin, as an MCAP file
// that Foxglove Studio and PlotJuggler open with no plugin: message encoding
// "json", schema encoding "jsonschema" (lcmtypes/gen_lcm_json.py writes one
// schema per LCM type), one MCAP channel per LCM channel, chunked and
// indexed, with a summary section and statistics.
//
//   node write_mcap.mjs --schemas DIR --out FILE.mcap < session.jsonl
//
// Each line is one message (scripts/lab export --mcap prints them):
//   {"channel": "RMS_DCP_FRAME", "type": "rms.dcp_frame_t",
//    "log_time_ns": 19733333333, "publish_time_ns": 1733090000000000000,
//    "message": {...}}
// channel: the LCM channel (the MCAP topic); type: the LCM type, PACKAGE.T,
// whose schema is DIR/PACKAGE.T.json; log_time_ns (the message's session
// time, ns from the session's first frame: docs/sessions.md "Session time")
// and publish_time_ns (optional, log_time_ns when absent; the sender's wall
// clock, ns since 1970): integers, read from the line's text exactly (beyond
// 2^53 too); message: the
// object, written byte for byte as it is on the line (int64 values stay
// exact). Blank lines are skipped; any other line that is not such an object
// is an error naming its line number: exit 1 and no output file.
//
// The lines are streamed (not held in memory). A message whose log time is
// earlier than its channel's previous one is written as it is (MCAP allows
// it) and counted. At the end, on stderr:
//   mcap: N messages on C channels, T types -> FILE (S MB)
import { constants, unlinkSync } from "node:fs";
import { randomBytes } from "node:crypto";
import { lstat, open, readFile, rename, stat, unlink } from "node:fs/promises";
import { basename, dirname, join, resolve } from "node:path";
import { StringDecoder } from "node:string_decoder";
import { parseArgs } from "node:util";

import { McapWriter, LIBRARY_IDENTIFIER } from "@mcap/core";

const KEYS = new Set(["channel", "type", "log_time_ns", "publish_time_ns", "message"]);
const TYPE_RE = /^[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z_][A-Za-z0-9_]*)*$/;
const UINT64_MAX = (1n << 64n) - 1n;

class InputError extends Error {}

// A path as the terminal may show it: control characters as \xNN, never
// obeyed (docs/security.md "Text from messages and folders").
function shown(text) {
  // eslint-disable-next-line no-control-regex
  return String(text).replace(/[\x00-\x08\x0b-\x1f\x7f\u0080-\u009f]/g,
      (c) => "\\x" + c.charCodeAt(0).toString(16).padStart(2, "0"));
}

function usage() {
  return "usage: node write_mcap.mjs --schemas DIR --out FILE.mcap [--follow-links] < session.jsonl";
}

// The raw text of each top-level value of a JSON object, by key. `text` must
// already be valid JSON (JSON.parse accepted it): this only finds the spans.
function topLevelSpans(text) {
  const spans = new Map();
  let i = 0;
  const ws = () => {
    while (i < text.length && " \t\r\n".includes(text[i])) i++;
  };
  const skipString = () => {
    i++; // opening quote
    while (text[i] !== '"') i += text[i] === "\\" ? 2 : 1;
    i++;
  };
  const skipValue = () => {
    const c = text[i];
    if (c === '"') return skipString();
    if (c === "{" || c === "[") {
      let depth = 0;
      do {
        const d = text[i];
        if (d === '"') {
          skipString();
          continue;
        }
        if (d === "{" || d === "[") depth++;
        else if (d === "}" || d === "]") depth--;
        i++;
      } while (depth > 0);
      return;
    }
    while (i < text.length && !",}] \t\r\n".includes(text[i])) i++;
  };
  ws();
  i++; // '{'
  ws();
  if (text[i] === "}") return spans;
  for (;;) {
    ws();
    const keyStart = i;
    skipString();
    const key = JSON.parse(text.slice(keyStart, i));
    ws();
    i++; // ':'
    ws();
    const start = i;
    skipValue();
    spans.set(key, [start, i]);
    ws();
    if (text[i++] === "}") return spans;
  }
}

function timeOf(obj, spans, line, key) {
  const v = obj[key];
  if (typeof v !== "number" || !Number.isInteger(v) || v < 0) {
    throw new InputError(`"${key}" must be a non-negative integer (ns since 1970), got ${JSON.stringify(v)}`);
  }
  const raw = line.slice(...spans.get(key));
  if (!/^(0|[1-9][0-9]*)$/.test(raw)) {
    throw new InputError(`"${key}" must be written as a plain integer (no fraction or exponent), got ${raw}`);
  }
  const t = BigInt(raw);
  if (t > UINT64_MAX) throw new InputError(`"${key}" ${raw} does not fit in 64 bits`);
  return t;
}

// One stdin line to {channel, type, logTime, publishTime, data}.
function parseLine(line) {
  let obj;
  try {
    obj = JSON.parse(line);
  } catch (e) {
    throw new InputError(`not JSON: ${e.message}`);
  }
  if (obj === null || typeof obj !== "object" || Array.isArray(obj)) {
    throw new InputError("not a JSON object");
  }
  for (const k of Object.keys(obj)) {
    if (!KEYS.has(k)) throw new InputError(`unknown key "${k}" (expected ${[...KEYS].join(", ")})`);
  }
  for (const k of ["channel", "type", "log_time_ns", "message"]) {
    if (!(k in obj)) throw new InputError(`missing "${k}"`);
  }
  if (typeof obj.channel !== "string" || obj.channel === "") {
    throw new InputError(`"channel" must be a non-empty string, got ${JSON.stringify(obj.channel)}`);
  }
  if (typeof obj.type !== "string" || !TYPE_RE.test(obj.type)) {
    throw new InputError(`"type" must be an LCM type name like "rms.dcp_frame_t", got ${JSON.stringify(obj.type)}`);
  }
  const m = obj.message;
  if (m === null || typeof m !== "object" || Array.isArray(m)) {
    throw new InputError(`"message" must be a JSON object`);
  }
  const spans = topLevelSpans(line);
  const logTime = timeOf(obj, spans, line, "log_time_ns");
  const publishTime = "publish_time_ns" in obj ? timeOf(obj, spans, line, "publish_time_ns") : logTime;
  const data = Buffer.from(line.slice(...spans.get("message")), "utf8");
  return { channel: obj.channel, type: obj.type, logTime, publishTime, data };
}

// stdin, line by line, with backpressure: the next chunk is read only when
// the lines before it have been written.
async function* lines(stream) {
  const decoder = new StringDecoder("utf8");
  let rest = "";
  for await (const chunk of stream) {
    const text = rest + decoder.write(chunk);
    const parts = text.split("\n");
    rest = parts.pop();
    yield* parts;
  }
  rest += decoder.end();
  if (rest !== "") yield rest;
}

// McapWriter's output: a file, written in order.
class FileWritable {
  constructor(handle) {
    this.handle = handle;
    this.offset = 0n;
  }
  async write(buffer) {
    let done = 0;
    while (done < buffer.byteLength) {
      const { bytesWritten } = await this.handle.write(buffer, done, buffer.byteLength - done);
      done += bytesWritten;
    }
    this.offset += BigInt(buffer.byteLength);
  }
  position() {
    return this.offset;
  }
}

async function main() {
  let args;
  try {
    ({ values: args } = parseArgs({
      options: {
        schemas: { type: "string" },
        out: { type: "string" },
        "follow-links": { type: "boolean" },
        help: { type: "boolean", short: "h" },
      },
      strict: true,
    }));
  } catch (e) {
    console.error(`write_mcap: ${e.message}\n${usage()}`);
    return 2;
  }
  if (args.help) {
    console.log(usage());
    return 0;
  }
  if (!args.schemas || !args.out) {
    console.error(`write_mcap: --schemas and --out are required\n${usage()}`);
    return 2;
  }
  const out = resolve(args.out);
  // Written directly only where the user named it (--follow-links: an --out
  // outside the session's folder) and it is a link, a FIFO or a device, or
  // anywhere under /dev or /proc (`--out /dev/stdout`); anything else to a
  // temporary file renamed over its name, so a link, FIFO or device planted
  // in a session's folder is replaced, never written through
  // (docs/security.md "Session folders are untrusted").
  const st = await lstat(out).catch(() => null);
  const direct =
      /^\/(dev|proc)\//.test(out) ||
      (args["follow-links"] && st !== null && !st.isFile() && !st.isDirectory());
  const tmp = direct ? out : join(dirname(out), `.${basename(out)}.${randomBytes(6).toString("hex")}.partial`);
  let handle;
  try {
    if (direct && (await stat(out).catch(() => null))?.isFIFO()) {
      // A FIFO nothing reads is refused, not waited on.
      const probe = await open(out, constants.O_WRONLY | constants.O_NONBLOCK).catch((e) => {
        throw new Error(e.code === "ENXIO" ? "a FIFO that nothing reads" : e.message);
      });
      await probe.close();
    }
    handle = await open(tmp, direct ? "w" : "wx");
  } catch (e) {
    console.error(`write_mcap: cannot write ${shown(args.out)}: ${e.message}`);
    return 1;
  }
  const writer = new McapWriter({ writable: new FileWritable(handle) });
  const schemaIds = new Map(); // type -> schema id
  const channels = new Map(); // channel -> {id, type, seq, lastLogTime}
  let count = 0;
  let backward = 0;
  let lineNo = 0;
  let ok = false;
  // Interrupted (the exporter's pipe closed on Ctrl-C, a timeout): no partial file.
  for (const sig of ["SIGINT", "SIGTERM", "SIGHUP"]) {
    process.on(sig, () => {
      try {
        if (!direct) unlinkSync(tmp);
      } catch {}
      console.error(`write_mcap: ${sig} after ${lineNo} lines; no output written`);
      process.exit(128 + ({ SIGHUP: 1, SIGINT: 2, SIGTERM: 15 })[sig]);
    });
  }
  try {
    await writer.start({ profile: "", library: `rmslab write_mcap.mjs (${LIBRARY_IDENTIFIER})` });
    for await (const raw of lines(process.stdin)) {
      lineNo++;
      const line = raw.endsWith("\r") ? raw.slice(0, -1) : raw;
      if (line.trim() === "") continue;
      let msg;
      try {
        msg = parseLine(line);
      } catch (e) {
        if (e instanceof InputError) throw new InputError(`line ${lineNo}: ${e.message}`);
        throw e;
      }
      let ch = channels.get(msg.channel);
      if (!ch) {
        let schemaId = schemaIds.get(msg.type);
        if (schemaId === undefined) {
          const file = join(args.schemas, `${msg.type}.json`);
          let bytes;
          try {
            bytes = await readFile(file);
            const schema = JSON.parse(bytes.toString("utf8"));
            if (schema === null || typeof schema !== "object" || schema.type !== "object") {
              throw new Error("not a JSON Schema of an object");
            }
          } catch (e) {
            throw new InputError(`line ${lineNo}: type ${msg.type}: no usable schema ${file}: ${e.message}`);
          }
          schemaId = await writer.registerSchema({ name: msg.type, encoding: "jsonschema", data: bytes });
          schemaIds.set(msg.type, schemaId);
        }
        const id = await writer.registerChannel({
          topic: msg.channel,
          messageEncoding: "json",
          schemaId,
          metadata: new Map([["lcm_type", msg.type]]),
        });
        ch = { id, type: msg.type, seq: 0, lastLogTime: msg.logTime };
        channels.set(msg.channel, ch);
      } else if (ch.type !== msg.type) {
        throw new InputError(`line ${lineNo}: channel ${msg.channel} has type ${ch.type} (earlier lines), not ${msg.type}`);
      }
      if (msg.logTime < ch.lastLogTime) backward++;
      ch.lastLogTime = msg.logTime;
      await writer.addMessage({
        channelId: ch.id,
        sequence: ch.seq++ % 2 ** 32,
        logTime: msg.logTime,
        publishTime: msg.publishTime,
        data: msg.data,
      });
      count++;
    }
    await writer.end();
    await handle.close();
    if (!direct) await rename(tmp, out);
    ok = true;
  } catch (e) {
    console.error(`write_mcap: ${e instanceof InputError ? e.message : e.stack || e}`);
  } finally {
    if (!ok) {
      await handle.close().catch(() => {});
      if (!direct) await unlink(tmp).catch(() => {});
    }
  }
  if (!ok) return 1;
  const bytes = (await stat(out)).size || 0;
  console.error(
    `mcap: ${count} messages on ${channels.size} channels, ${schemaIds.size} types -> ${shown(args.out)} (${(bytes / 1e6).toFixed(2)} MB)`,
  );
  if (backward > 0) {
    console.error(`mcap: ${backward} messages earlier than their channel's previous one (written in input order)`);
  }
  return 0;
}

process.exitCode = await main();
