// An MCAP fixture written by the official writer (@mcap/core's McapWriter,
// messages serialized by @foxglove/rosmsg2-serialization), to check the
// package's reader against it: /imu0 (sensor_msgs/msg/Imu, CDR, 200
// messages at 200 Hz) beside /cam0/image_raw (sensor_msgs/msg/Image, 32x24
// mono8 at 10 Hz), in chunks of about 16 kB, with the summary (statistics,
// chunk indexes, message indexes). Writes, into the directory given:
//   mcap_official.mcap      uncompressed chunks
//   mcap_official_zstd.mcap zstd chunks (when @foxglove/wasm-zstd is there)
//   mcap_official_imu.csv   the IMU values written, Kalibr CSV, 17 digits
//
//   mkdir /tmp/m && cd /tmp/m && npm install @mcap/core @foxglove/rosmsg \
//     @foxglove/rosmsg2-serialization @foxglove/wasm-zstd
//   NODE_PATH=/tmp/m/node_modules node tools/make-mcap-official.js tests/testthat/fixtures/ros
const fs = require("fs");
const path = require("path");
const { McapWriter, TempBuffer } = require("@mcap/core");
const { parse } = require("@foxglove/rosmsg");
const { MessageWriter } = require("@foxglove/rosmsg2-serialization");

const out = process.argv[2] || path.join("tests", "testthat", "fixtures", "ros");
const sep = "\n================================================================================\n";
const common = [
  "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id",
  "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec",
].join(sep);
const imuDef = [
  "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\nfloat64[9] orientation_covariance\n" +
    "geometry_msgs/Vector3 angular_velocity\nfloat64[9] angular_velocity_covariance\n" +
    "geometry_msgs/Vector3 linear_acceleration\nfloat64[9] linear_acceleration_covariance",
  common,
  "MSG: geometry_msgs/Quaternion\nfloat64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1",
  "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z",
].join(sep);
const imgDef = [
  "std_msgs/Header header\nuint32 height\nuint32 width\nstring encoding\nuint8 is_bigendian\n" +
    "uint32 step\nuint8[] data",
  common,
].join(sep);

// A small deterministic generator (xorshift32) and Box-Muller normals.
let state = 28;
function unif() {
  state ^= state << 13; state >>>= 0;
  state ^= state >>> 17;
  state ^= state << 5; state >>>= 0;
  return (state + 0.5) / 4294967296;
}
function gauss(sd) {
  return sd * Math.sqrt(-2 * Math.log(unif())) * Math.cos(2 * Math.PI * unif());
}

async function write(file, compressChunk) {
  state = 28;
  const buf = new TempBuffer();
  const w = new McapWriter({ writable: buf, chunkSize: 16 * 1024, compressChunk });
  await w.start({ profile: "ros2", library: "mcap-js (allanvar fixture)" });
  const imuSchema = await w.registerSchema({ name: "sensor_msgs/msg/Imu", encoding: "ros2msg",
                                             data: new TextEncoder().encode(imuDef) });
  const imgSchema = await w.registerSchema({ name: "sensor_msgs/msg/Image", encoding: "ros2msg",
                                             data: new TextEncoder().encode(imgDef) });
  const imuCh = await w.registerChannel({ schemaId: imuSchema, topic: "/imu0", messageEncoding: "cdr", metadata: new Map() });
  const imgCh = await w.registerChannel({ schemaId: imgSchema, topic: "/cam0/image_raw", messageEncoding: "cdr", metadata: new Map() });
  const imuW = new MessageWriter(parse(imuDef, { ros2: true }));
  const imgW = new MessageWriter(parse(imgDef, { ros2: true }));
  const t0 = 1700000000n * 1000000000n;
  const ev = [];
  for (let i = 0; i < 200; i++) ev.push([i * 5000000, 0, i]);
  for (let j = 0; j < 10; j++) ev.push([j * 100000000 + 2500000, 1, j]);
  ev.sort((a, b) => a[0] - b[0] || a[1] - b[1]);
  const rows = [];
  for (const [ns, kind, i] of ev) {
    const t = t0 + BigInt(ns);
    const stamp = { sec: 1700000000 + Math.floor(ns / 1e9), nanosec: ns % 1e9 };
    let data, ch;
    if (kind === 0) {
      const g = [gauss(0.01), gauss(0.01), gauss(0.01)];
      const a = [gauss(0.02), gauss(0.02), gauss(0.02) + 9.81];
      rows.push([t, g, a]);
      data = imuW.writeMessage({
        header: { stamp, frame_id: "imu" },
        orientation: { x: 0, y: 0, z: 0, w: 1 }, orientation_covariance: new Array(9).fill(0),
        angular_velocity: { x: g[0], y: g[1], z: g[2] }, angular_velocity_covariance: new Array(9).fill(0),
        linear_acceleration: { x: a[0], y: a[1], z: a[2] }, linear_acceleration_covariance: new Array(9).fill(0),
      });
      ch = imuCh;
    } else {
      const px = new Uint8Array(32 * 24);
      for (let k = 0; k < px.length; k++) px[k] = Math.floor(unif() * 256);
      data = imgW.writeMessage({ header: { stamp, frame_id: "cam0" }, height: 24, width: 32,
                                 encoding: "mono8", is_bigendian: 0, step: 32, data: px });
      ch = imgCh;
    }
    // Received 1 ms after the stamp.
    await w.addMessage({ channelId: ch, sequence: i, logTime: t + 1000000n, publishTime: t, data });
  }
  await w.end();
  fs.writeFileSync(file, buf.get());
  return rows;
}

(async () => {
  fs.mkdirSync(out, { recursive: true });
  const rows = await write(path.join(out, "mcap_official.mcap"), undefined);
  let zstd = null;
  try { zstd = require("@foxglove/wasm-zstd"); } catch (e) { zstd = null; }
  if (zstd) {
    await zstd.isLoaded;
    await write(path.join(out, "mcap_official_zstd.mcap"),
                (d) => ({ compression: "zstd", compressedData: zstd.compress(d, 3) }));
  }
  const f17 = (v) => v.toPrecision(17);
  const lines = ["timestamp,omega_x,omega_y,omega_z,alpha_x,alpha_y,alpha_z"];
  for (const [t, g, a] of rows) lines.push([t.toString(), ...g.map(f17), ...a.map(f17)].join(","));
  fs.writeFileSync(path.join(out, "mcap_official_imu.csv"), lines.join("\n") + "\n");
})();
