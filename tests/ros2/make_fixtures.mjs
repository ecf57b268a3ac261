// Writes ROS 2 bags with writers that are not ours, for the tests of our MCAP, CDR and rosbag2
// readers: Foxglove's MCAP writer (@mcap/core), its ROS 2 CDR serialiser
// (@foxglove/rosmsg2-serialization) and SQLite compiled to WebAssembly (sql.js) for rosbag2's
// sqlite3 storage.
//
//   node make_fixtures.mjs --modules DIR/node_modules --out DIR [--data REPLAY_FOLDER]
//
// Always writes raw.mcap (raw images in mono8, rgb8 and bgr8 with known pixels, an IMU and an
// odometry message with known values; zstd chunks), and the same as raw_lz4.mcap,
// raw_nosummary.mcap, raw_channels_only.mcap (a summary repeating channels but not their
// schemas) and raw_db3/ (a sqlite3 rosbag2 folder). With --data, writes that replay folder's images (as PNG
// CompressedImage), odometry, ground truth (PoseStamped) and headings (Imu orientation) as
// loop_zstd.mcap, loop_lz4.mcap, loop_plain.mcap (uncompressed chunks), loop_nosummary.mcap (no
// chunks, no index, no summary section: readers must scan), loop_db3/ (a rosbag2 folder with
// metadata.yaml and a sqlite3 file) and loop_mcap_dir/ (a rosbag2 folder holding an MCAP file).
// Stamps are 1e9 s plus the folder's times, converted from their decimal text exactly.
import fs from "node:fs";
import path from "node:path";
import { createRequire } from "node:module";

const args = Object.fromEntries(
  process.argv.slice(2).reduce((pairs, a, i, all) => {
    if (a.startsWith("--")) pairs.push([a.slice(2), all[i + 1]]);
    return pairs;
  }, []),
);
if (!args.modules || !args.out) {
  console.error("usage: make_fixtures.mjs --modules DIR/node_modules --out DIR [--data FOLDER]");
  process.exit(2);
}
const require = createRequire(path.join(path.resolve(args.modules), "..", "package.json"));
const { McapWriter } = require("@mcap/core");
const { parse } = require("@foxglove/rosmsg");
const { MessageWriter } = require("@foxglove/rosmsg2-serialization");
const zstd = require("@foxglove/wasm-zstd");
const lz4 = require("lz4js");
const initSqlJs = require("sql.js");

// ROS 2 message definitions (the layouts of the Humble/Iron message packages), in the
// concatenated form rosbag2 stores as an MCAP schema.
const SEP = "\n================================================================================\n";
const DEF = {
  header: "builtin_interfaces/Time stamp\nstring frame_id",
  time: "int32 sec\nuint32 nanosec",
  point: "float64 x\nfloat64 y\nfloat64 z",
  quaternion: "float64 x\nfloat64 y\nfloat64 z\nfloat64 w",
  vector3: "float64 x\nfloat64 y\nfloat64 z",
  pose: "geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation",
  twist: "geometry_msgs/Vector3 linear\ngeometry_msgs/Vector3 angular",
};
const sub = (name, def) => `${SEP}MSG: ${name}\n${def}`;
const common = sub("std_msgs/Header", DEF.header) + sub("builtin_interfaces/Time", DEF.time);
const geometry =
  sub("geometry_msgs/Pose", DEF.pose) +
  sub("geometry_msgs/Point", DEF.point) +
  sub("geometry_msgs/Quaternion", DEF.quaternion);
const SCHEMAS = {
  "sensor_msgs/msg/Image":
    "std_msgs/Header header\nuint32 height\nuint32 width\nstring encoding\nuint8 is_bigendian\n" +
    "uint32 step\nuint8[] data" +
    common,
  "sensor_msgs/msg/CompressedImage": "std_msgs/Header header\nstring format\nuint8[] data" + common,
  "nav_msgs/msg/Odometry":
    "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/PoseWithCovariance pose\n" +
    "geometry_msgs/TwistWithCovariance twist" +
    common +
    sub("geometry_msgs/PoseWithCovariance", "geometry_msgs/Pose pose\nfloat64[36] covariance") +
    geometry +
    sub("geometry_msgs/TwistWithCovariance", "geometry_msgs/Twist twist\nfloat64[36] covariance") +
    sub("geometry_msgs/Twist", DEF.twist) +
    sub("geometry_msgs/Vector3", DEF.vector3),
  "geometry_msgs/msg/PoseStamped": "std_msgs/Header header\ngeometry_msgs/Pose pose" + common + geometry,
  "sensor_msgs/msg/Imu":
    "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\n" +
    "float64[9] orientation_covariance\ngeometry_msgs/Vector3 angular_velocity\n" +
    "float64[9] angular_velocity_covariance\ngeometry_msgs/Vector3 linear_acceleration\n" +
    "float64[9] linear_acceleration_covariance" +
    common +
    sub("geometry_msgs/Quaternion", DEF.quaternion) +
    sub("geometry_msgs/Vector3", DEF.vector3),
};
const writers = Object.fromEntries(
  Object.entries(SCHEMAS).map(([name, text]) => [name, new MessageWriter(parse(text, { ros2: true }))]),
);
const serialise = (type, message) => writers[type].writeMessage(message);

const OFFSET_NS = 1000000000n * 1000000000n;
// "12.3" -> 12300000000n, exactly (no binary floating point on the way).
function decimalToNs(text) {
  const m = /^(-?)(\d+)(?:\.(\d{0,9}))?$/.exec(text.trim());
  if (!m) throw new Error(`time '${text}' is not a decimal with at most 9 places`);
  const ns = BigInt(m[2]) * 1000000000n + BigInt((m[3] || "").padEnd(9, "0"));
  return m[1] ? -ns : ns;
}
const stampOf = (ns) => ({ sec: Number(ns / 1000000000n), nanosec: Number(ns % 1000000000n) });
const header = (ns, frame) => ({ stamp: stampOf(ns), frame_id: frame });
const yawQuaternion = (yaw) => ({ x: 0, y: 0, z: Math.sin(yaw / 2), w: Math.cos(yaw / 2) });
const zeros = (n) => new Array(n).fill(0);

function readCsv(file) {
  const lines = fs.readFileSync(file, "utf8").split("\n").filter((l) => l.trim() !== "");
  const names = lines[0].split(",");
  return lines.slice(1).map((l) => {
    const cells = l.split(",");
    return Object.fromEntries(names.map((n, i) => [n, cells[i]]));
  });
}

// The folder's streams as [topic, type, ns, message] in time order (stable by stream).
function messagesOf(folder) {
  const out = [];
  for (const row of readCsv(path.join(folder, "images.csv"))) {
    const ns = OFFSET_NS + decimalToNs(row.time_s);
    const png = fs.readFileSync(path.join(folder, "images", row.file));
    out.push(["/camera/image/compressed", "sensor_msgs/msg/CompressedImage", ns,
      { header: header(ns, "camera"), format: "png", data: new Uint8Array(png) }]);
  }
  for (const row of readCsv(path.join(folder, "odometry.csv"))) {
    const ns = OFFSET_NS + decimalToNs(row.time_s);
    out.push(["/odom", "nav_msgs/msg/Odometry", ns, {
      header: header(ns, "odom"),
      child_frame_id: "base_link",
      pose: { pose: { position: { x: 0, y: 0, z: 0 }, orientation: yawQuaternion(0) }, covariance: zeros(36) },
      twist: {
        twist: {
          linear: { x: parseFloat(row.forward_speed_m_per_s), y: 0, z: 0 },
          angular: { x: 0, y: 0, z: parseFloat(row.turn_rate_rad_per_s) },
        },
        covariance: zeros(36),
      },
    }]);
  }
  for (const row of readCsv(path.join(folder, "ground_truth.csv"))) {
    const ns = OFFSET_NS + decimalToNs(row.time_s);
    const yaw = parseFloat(row.theta_rad);
    out.push(["/ground_truth", "geometry_msgs/msg/PoseStamped", ns, {
      header: header(ns, "map"),
      pose: { position: { x: parseFloat(row.x_m), y: parseFloat(row.y_m), z: 0 }, orientation: yawQuaternion(yaw) },
    }]);
    out.push(["/imu", "sensor_msgs/msg/Imu", ns, {
      header: header(ns, "imu"),
      orientation: yawQuaternion(yaw),
      orientation_covariance: zeros(9),
      angular_velocity: { x: 0, y: 0, z: 0 },
      angular_velocity_covariance: zeros(9),
      linear_acceleration: { x: 0, y: 0, z: 9.81 },
      linear_acceleration_covariance: zeros(9),
    }]);
  }
  return out.map((m, i) => [...m, i]).sort((a, b) => (a[2] < b[2] ? -1 : a[2] > b[2] ? 1 : a[4] - b[4]));
}

class FileSink {
  constructor() { this.parts = []; this.size = 0n; }
  async write(buffer) { this.parts.push(Buffer.from(buffer)); this.size += BigInt(buffer.byteLength); }
  position() { return this.size; }
  bytes() { return Buffer.concat(this.parts); }
}

const COMPRESSORS = {
  zstd: (data) => ({ compression: "zstd", compressedData: zstd.compress(data, 3) }),
  lz4: (data) => ({ compression: "lz4", compressedData: Uint8Array.from(lz4.compress(data)) }),
  plain: (data) => ({ compression: "", compressedData: data }),
};

async function writeMcap(file, messages, { compression, indexed = true, chunkSize = 64 * 1024, repeatSchemas = true }) {
  const sink = new FileSink();
  const options = { writable: sink, chunkSize, repeatSchemas };
  if (compression) options.compressChunk = COMPRESSORS[compression];
  if (!indexed) {
    Object.assign(options, {
      useChunks: false, useStatistics: false, useSummaryOffsets: false, useChunkIndex: false,
      useMessageIndex: false, useAttachmentIndex: false, useMetadataIndex: false,
      repeatSchemas: false, repeatChannels: false,
    });
  }
  const writer = new McapWriter(options);
  await writer.start({ profile: "ros2", library: "ratslam test fixtures (@mcap/core)" });
  const channels = new Map();
  const sequence = new Map();
  for (const [topic, type, ns, message] of messages) {
    if (!channels.has(topic)) {
      const schemaId = await writer.registerSchema({
        name: type, encoding: "ros2msg", data: new TextEncoder().encode(SCHEMAS[type]),
      });
      channels.set(topic, await writer.registerChannel({
        topic, schemaId, messageEncoding: "cdr", metadata: new Map([["offered_qos_profiles", ""]]),
      }));
    }
    const n = (sequence.get(topic) || 0) + 1;
    sequence.set(topic, n);
    await writer.addMessage({
      channelId: channels.get(topic), sequence: n, logTime: ns, publishTime: ns,
      data: serialise(type, message),
    });
  }
  await writer.end();
  fs.writeFileSync(file, sink.bytes());
}

function metadataYaml(storage, files, messages) {
  const topics = [...new Map(messages.map(([topic, type]) => [topic, type])).entries()];
  const counts = (topic) => messages.filter((m) => m[0] === topic).length;
  const start = messages.length ? messages[0][2] : 0n;
  const end = messages.length ? messages[messages.length - 1][2] : 0n;
  return [
    "rosbag2_bagfile_information:",
    "  version: 5",
    `  storage_identifier: ${storage}`,
    "  duration:",
    `    nanoseconds: ${end - start}`,
    "  starting_time:",
    `    nanoseconds_since_epoch: ${start}`,
    `  message_count: ${messages.length}`,
    "  topics_with_message_count:",
    ...topics.flatMap(([topic, type]) => [
      "    - topic_metadata:",
      `        name: ${topic}`,
      `        type: ${type}`,
      "        serialization_format: cdr",
      "        offered_qos_profiles: \"\"",
      `      message_count: ${counts(topic)}`,
    ]),
    "  compression_format: \"\"",
    "  compression_mode: \"\"",
    "  relative_file_paths:",
    ...files.map((f) => `    - ${f}`),
    "  files:",
    ...files.flatMap((f) => [`    - path: ${f}`, `      message_count: ${messages.length}`]),
    "",
  ].join("\n");
}

async function writeDb3Folder(folder, messages) {
  fs.mkdirSync(folder, { recursive: true });
  const SQL = await initSqlJs();
  const db = new SQL.Database();
  // rosbag2's sqlite3 storage schema (the tables its plugin creates).
  db.run(
    "CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL);" +
      "INSERT INTO schema VALUES (3, 'humble');" +
      "CREATE TABLE metadata(id INTEGER PRIMARY KEY, metadata_version INTEGER NOT NULL, metadata TEXT NOT NULL);" +
      "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, " +
      "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);" +
      "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, data BLOB NOT NULL);" +
      "CREATE INDEX timestamp_idx ON messages (timestamp ASC);",
  );
  const ids = new Map();
  for (const [topic, type] of messages) {
    if (ids.has(topic)) continue;
    ids.set(topic, ids.size + 1);
    db.run("INSERT INTO topics VALUES (?, ?, ?, 'cdr', '')", [ids.get(topic), topic, type]);
  }
  const insert = db.prepare("INSERT INTO messages (topic_id, timestamp, data) VALUES (?, ?, ?)");
  for (const [topic, type, ns, message] of messages) {
    // sql.js binds JavaScript numbers; the stamps (about 1e18) need 64-bit integers, which
    // pass exactly as text that SQLite converts on an INTEGER column.
    insert.run([ids.get(topic), ns.toString(), serialise(type, message)]);
  }
  insert.free();
  const file = `${path.basename(folder)}_0.db3`;
  fs.writeFileSync(path.join(folder, file), Buffer.from(db.export()));
  db.close();
  fs.writeFileSync(path.join(folder, "metadata.yaml"), metadataYaml("sqlite3", [file], messages));
}

// Raw images with known pixels: mono8 2x3 (0..250 in steps of 50), rgb8 and bgr8 2x2 with pure
// red, green, blue and white, row padding in rgb8 (step 8 for 6 bytes).
function rawMessages() {
  const t = (k) => OFFSET_NS + BigInt(k) * 100000000n;
  const image = (ns, h, w, encoding, step, data) => ({
    header: header(ns, "camera"), height: h, width: w, encoding, is_bigendian: 0, step, data: Uint8Array.from(data),
  });
  return [
    ["/camera/image_raw", "sensor_msgs/msg/Image", t(0), image(t(0), 2, 3, "mono8", 3, [0, 50, 100, 150, 200, 250])],
    ["/camera/image_raw", "sensor_msgs/msg/Image", t(1),
      image(t(1), 2, 2, "rgb8", 8, [255, 0, 0, 0, 255, 0, 9, 9, 0, 0, 255, 255, 255, 255, 9, 9])],
    ["/camera/image_raw", "sensor_msgs/msg/Image", t(2),
      image(t(2), 2, 2, "bgr8", 6, [0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255])],
    ["/imu", "sensor_msgs/msg/Imu", t(1), {
      header: header(t(1), "imu"), orientation: yawQuaternion(0.75), orientation_covariance: zeros(9),
      angular_velocity: { x: 0, y: 0, z: 0 }, angular_velocity_covariance: zeros(9),
      linear_acceleration: { x: 0, y: 0, z: 9.81 }, linear_acceleration_covariance: zeros(9),
    }],
    ["/odom", "nav_msgs/msg/Odometry", t(2), {
      header: header(t(2), "odom"), child_frame_id: "base_link",
      pose: { pose: { position: { x: 1, y: 2, z: 0 }, orientation: yawQuaternion(0) }, covariance: zeros(36) },
      twist: { twist: { linear: { x: 0.5, y: 0, z: 0 }, angular: { x: 0, y: 0, z: -0.25 } }, covariance: zeros(36) },
    }],
  ].sort((a, b) => (a[2] < b[2] ? -1 : a[2] > b[2] ? 1 : 0));
}

await zstd.isLoaded;
fs.mkdirSync(args.out, { recursive: true });
await writeMcap(path.join(args.out, "raw.mcap"), rawMessages(), { compression: "zstd" });
await writeMcap(path.join(args.out, "raw_lz4.mcap"), rawMessages(), { compression: "lz4" });
await writeMcap(path.join(args.out, "raw_nosummary.mcap"), rawMessages(), { indexed: false });
await writeMcap(path.join(args.out, "raw_channels_only.mcap"), rawMessages(), { compression: "zstd", repeatSchemas: false });
await writeDb3Folder(path.join(args.out, "raw_db3"), rawMessages());
if (args.data) {
  const messages = messagesOf(args.data);
  await writeMcap(path.join(args.out, "loop_zstd.mcap"), messages, { compression: "zstd" });
  await writeMcap(path.join(args.out, "loop_lz4.mcap"), messages, { compression: "lz4" });
  await writeMcap(path.join(args.out, "loop_plain.mcap"), messages, { compression: "plain" });
  await writeMcap(path.join(args.out, "loop_nosummary.mcap"), messages, { indexed: false });
  await writeDb3Folder(path.join(args.out, "loop_db3"), messages);
  const dir = path.join(args.out, "loop_mcap_dir");
  fs.mkdirSync(dir, { recursive: true });
  await writeMcap(path.join(dir, "loop_mcap_dir_0.mcap"), messages, { compression: "zstd" });
  fs.writeFileSync(path.join(dir, "metadata.yaml"), metadataYaml("mcap", ["loop_mcap_dir_0.mcap"], messages));
}
