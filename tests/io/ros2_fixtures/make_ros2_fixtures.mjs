// make_ros2_fixtures.mjs — writes ROS 2 bags from the messages of a ROS 1 bag, with writers
// independent of plumb: the MCAP library @mcap/core and the CDR serializer
// @foxglove/rosmsg2-serialization (versions pinned in package.json / package-lock.json,
// installed by scripts/setup into .deps/ros2-fixtures with `npm ci`; never committed).
//
//   node make_ros2_fixtures.mjs DEPS_DIR MESSAGES.json OUT_PREFIX [CHUNK_BYTES]
//
// MESSAGES.json: dump_ros1_bag.py's output (every message of the bag, exact doubles). Writes
//   OUT_PREFIX.mcap        chunks uncompressed
//   OUT_PREFIX_zstd.mcap   chunks zstd (@foxglove/wasm-zstd)
//   OUT_PREFIX_lz4.mcap    chunks lz4, the LZ4 frame format (lz4js)
//   OUT_PREFIX.cdr.json    the topics and each message's CDR bytes (base64) and receive time,
//                          for make_db3.py to write the .db3 bag from
// Each message's log_time (the recorder's receive time) is the ROS 1 record time, its
// publish_time the header stamp; sensor_msgs/Imu and sensor_msgs/MagneticField become
// sensor_msgs/msg/Imu and sensor_msgs/msg/MagneticField (the header's seq dropped, as ROS 2
// has none).
import { createRequire } from "node:module";
import { readFileSync, writeFileSync } from "node:fs";
import path from "node:path";

const [depsDir, messagesPath, outPrefix, chunkArg] = process.argv.slice(2);
if (!outPrefix) {
  console.error("usage: node make_ros2_fixtures.mjs DEPS_DIR MESSAGES.json OUT_PREFIX [CHUNK_BYTES]");
  process.exit(2);
}
const require = createRequire(path.resolve(depsDir, "package.json"));
const { McapWriter, TempBuffer } = require("@mcap/core");
const { MessageWriter } = require("@foxglove/rosmsg2-serialization");
const { parse } = require("@foxglove/rosmsg");
const zstd = require("@foxglove/wasm-zstd");
const lz4js = require("lz4js");

// The ROS 2 message definitions, in the concatenated form rosbag2 stores as the schema.
const HEADER = `builtin_interfaces/Time stamp
string frame_id
================================================================================
MSG: builtin_interfaces/Time
int32 sec
uint32 nanosec`;
const QUATERNION = `MSG: geometry_msgs/Quaternion
float64 x 0
float64 y 0
float64 z 0
float64 w 1`;
const VECTOR3 = `MSG: geometry_msgs/Vector3
float64 x
float64 y
float64 z`;
const SEP = "\n================================================================================\n";
const DEFINITIONS = {
  "sensor_msgs/Imu": {
    name: "sensor_msgs/msg/Imu",
    text: `std_msgs/Header header
geometry_msgs/Quaternion orientation
float64[9] orientation_covariance
geometry_msgs/Vector3 angular_velocity
float64[9] angular_velocity_covariance
geometry_msgs/Vector3 linear_acceleration
float64[9] linear_acceleration_covariance` + SEP + "MSG: std_msgs/Header\n" + HEADER + SEP +
      QUATERNION + SEP + VECTOR3,
  },
  "sensor_msgs/MagneticField": {
    name: "sensor_msgs/msg/MagneticField",
    text: `std_msgs/Header header
geometry_msgs/Vector3 magnetic_field
float64[9] magnetic_field_covariance` + SEP + "MSG: std_msgs/Header\n" + HEADER + SEP + VECTOR3,
  },
};
const writers = {};
for (const [ros1, d] of Object.entries(DEFINITIONS)) {
  writers[ros1] = new MessageWriter(parse(d.text, { ros2: true }));
}

// dump_ros1_bag.py writes NaN and the infinities as strings.
const NON_FINITE = { NaN: NaN, Infinity: Infinity, "-Infinity": -Infinity };
const input = JSON.parse(readFileSync(messagesPath, "utf8"),
                         (key, value) => (typeof value === "string" && value in NON_FINITE
                                          && key !== "frame_id" && key !== "topic" && key !== "type"
                                          ? NON_FINITE[value] : value));
const nanos = (sec, nsec) => BigInt(sec) * 1000000000n + BigInt(nsec);
// Serialized once: every file holds the same bytes.
const messages = input.messages.map((m) => ({
  topic: m.topic,
  type: m.type,
  logTime: nanos(m.receive.sec, m.receive.nsec),
  publishTime: nanos(m.msg.header.stamp.sec, m.msg.header.stamp.nanosec),
  data: writers[m.type].writeMessage(m.msg),
}));

async function writeMcap(file, compressChunk) {
  const buffer = new TempBuffer();
  const writer = new McapWriter({
    writable: buffer,
    chunkSize: Number(chunkArg ?? 256 * 1024),
    compressChunk,
  });
  await writer.start({ profile: "ros2", library: "plumb tests/io/ros2_fixtures (@mcap/core 2.2.2)" });
  const channels = {};
  let sequence = 0;
  for (const m of messages) {
    if (!(m.topic in channels)) {
      const d = DEFINITIONS[m.type];
      const schemaId = await writer.registerSchema({
        name: d.name, encoding: "ros2msg", data: new TextEncoder().encode(d.text),
      });
      channels[m.topic] = await writer.registerChannel({
        schemaId, topic: m.topic, messageEncoding: "cdr", metadata: new Map(),
      });
    }
    await writer.addMessage({
      channelId: channels[m.topic], sequence: sequence++, logTime: m.logTime,
      publishTime: m.publishTime, data: m.data,
    });
  }
  await writer.end();
  writeFileSync(file, buffer.get());
}

await zstd.isLoaded;
await writeMcap(`${outPrefix}.mcap`, undefined);
await writeMcap(`${outPrefix}_zstd.mcap`, (data) => ({
  compression: "zstd", compressedData: zstd.compress(data, 3),
}));
await writeMcap(`${outPrefix}_lz4.mcap`, (data) => ({
  compression: "lz4", compressedData: Uint8Array.from(lz4js.compress(data)),
}));

const topics = [];
for (const m of messages) {
  if (!topics.some((t) => t.name === m.topic)) {
    topics.push({ name: m.topic, type: DEFINITIONS[m.type].name });
  }
}
writeFileSync(`${outPrefix}.cdr.json`, JSON.stringify({
  topics,
  messages: messages.map((m) => ({
    topic: m.topic, timestamp: m.logTime.toString(), data: Buffer.from(m.data).toString("base64"),
  })),
}));
