# The bench's bag and MCAP writers (bench/bench-bigbag.R) checked against
# the formats' own readers: small files written by the bench script, read
# by Debian's python3-rosbag and by @mcap/core's indexed reader (messages
# deserialized by @foxglove/rosmsg2-serialization), and by read_imu(); the
# IMU values, stamps and message counts must agree exactly.
#
#   NODE_PATH=/tmp/m/node_modules R_LIBS=<lib> Rscript tools/check-bench-writers.R
# (npm packages as in tools/make-mcap-official.js, plus @foxglove/wasm-lz4
# not needed; python3-rosbag, python3-sensor-msgs, python3-roslz4.)
suppressMessages(library(allanvar))
dir <- tempfile("benchw")
dir.create(dir)
Sys.setenv(ALLANVAR_BENCH_WRITE_ONLY = "1")
st <- system2(file.path(R.home("bin"), "Rscript"), c("bench/bench-bigbag.R", "0.01", dir))
stopifnot(st == 0)

py <- '
import rosbag, sys
b = rosbag.Bag(sys.argv[1])
n = {}
for topic, m, t in b.read_messages():
    n[topic] = n.get(topic, 0) + 1
    if topic == "/imu0":
        print("%d,%d,%s" % (m.header.stamp.secs, m.header.stamp.nsecs, ",".join("%.17g" % v for v in (
            m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z,
            m.linear_acceleration.x, m.linear_acceleration.y, m.linear_acceleration.z))))
    else:
        assert (m.height, m.width, m.encoding, len(m.data)) == (480, 640, "mono8", 640 * 480)
sys.stderr.write("%s\\n" % n)
'
js <- '
const fs = require("fs");
const { McapIndexedReader } = require("@mcap/core");
const { parse } = require("@foxglove/rosmsg");
const { MessageReader } = require("@foxglove/rosmsg2-serialization");
const imuDef = "std_msgs/Header header\\ngeometry_msgs/Quaternion orientation\\nfloat64[9] orientation_covariance\\ngeometry_msgs/Vector3 angular_velocity\\nfloat64[9] angular_velocity_covariance\\ngeometry_msgs/Vector3 linear_acceleration\\nfloat64[9] linear_acceleration_covariance\\n================================================================================\\nMSG: std_msgs/Header\\nbuiltin_interfaces/Time stamp\\nstring frame_id\\n================================================================================\\nMSG: builtin_interfaces/Time\\nint32 sec\\nuint32 nanosec\\n================================================================================\\nMSG: geometry_msgs/Quaternion\\nfloat64 x\\nfloat64 y\\nfloat64 z\\nfloat64 w\\n================================================================================\\nMSG: geometry_msgs/Vector3\\nfloat64 x\\nfloat64 y\\nfloat64 z";
(async () => {
  const zstd = require("@foxglove/wasm-zstd");
  await zstd.isLoaded;
  const buf = fs.readFileSync(process.argv[2]);
  const readable = { size: async () => BigInt(buf.length),
                     read: async (o, n) => buf.subarray(Number(o), Number(o) + Number(n)) };
  const r = await McapIndexedReader.Initialize({ readable,
    decompressHandlers: { zstd: (d, n) => zstd.decompress(d, Number(n)) } });
  const topic = new Map([...r.channelsById].map(([id, c]) => [id, c.topic]));
  const rd = new MessageReader(parse(imuDef, { ros2: true }));
  const n = {};
  const out = [];
  for await (const m of r.readMessages()) {
    const tp = topic.get(m.channelId);
    n[tp] = (n[tp] || 0) + 1;
    if (tp !== "/imu0") continue;
    const x = rd.readMessage(m.data);
    const v = [x.angular_velocity.x, x.angular_velocity.y, x.angular_velocity.z,
               x.linear_acceleration.x, x.linear_acceleration.y, x.linear_acceleration.z];
    out.push([x.header.stamp.sec, x.header.stamp.nanosec, ...v.map((u) => u.toPrecision(17))].join(","));
  }
  process.stderr.write(JSON.stringify(n) + "\\n");
  process.stdout.write(out.join("\\n") + "\\n");
})();
'
pyf <- tempfile(fileext = ".py"); writeLines(py, pyf)
jsf <- tempfile(fileext = ".js"); writeLines(js, jsf)
for (f in list.files(dir, full.names = TRUE)) {
  ours <- read_imu(f, topic = "/imu0")
  theirs <- if (grepl("[.]bag$", f)) {
    system2("/usr/bin/python3", c(pyf, f), stdout = TRUE)
  } else {
    system2("node", c(jsf, f), stdout = TRUE)
  }
  x <- utils::read.csv(text = theirs, header = FALSE)
  # Stamps in ns as integers: read_imu()'s times are (ns - first ns) / 1e9.
  ns <- (x[, 1] - x[1, 1]) * 1e9 + (x[, 2] - x[1, 2])
  same <- nrow(x) == nrow(ours$data) && identical(unname(as.matrix(x[, 3:8])), unname(ours$data[, 1:6])) &&
    identical(ns / 1e9, ours$time)
  if (!same) print(c(nrow(x), nrow(ours$data), max(abs(as.matrix(x[, 3:8]) - ours$data[, 1:6])), max(abs(ns / 1e9 - ours$time))))
  cat(sprintf("%-14s %6d IMU messages, the format's own reader and read_imu() %s\n",
              basename(f), nrow(x), if (same) "agree exactly" else "DIFFER"))
}
unlink(dir, recursive = TRUE)
