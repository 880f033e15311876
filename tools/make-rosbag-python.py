#!/usr/bin/python3
# Fixtures written by the real ROS1 library (Debian's python3-rosbag,
# python3-sensor-msgs, python3-roslz4), to check the package's own bag
# reader and writer against it: /imu0 (sensor_msgs/Imu, 200 messages at
# 200 Hz) beside /cam0/image_raw (sensor_msgs/Image, 32x24 mono8 at 10 Hz),
# header stamps 1 ms before the receive times. Writes, into the directory
# given (default tests/testthat/fixtures/ros):
#   rosbag_imu.csv        the IMU values written, Kalibr CSV, 17 digits
#   rosbag_none.bag       uncompressed chunks of about 16 kB
#   rosbag_lz4.bag        lz4 chunks
#   rosbag_unindexed.bag  the uncompressed bag copied before close():
#                         no index, the last chunk cut off (a recording
#                         that was killed)
#
#   /usr/bin/python3 tools/make-rosbag-python.py [dir]
import math
import os
import random
import shutil
import sys

import rosbag
from genpy import Time
from sensor_msgs.msg import Image, Imu

out = sys.argv[1] if len(sys.argv) > 1 else os.path.join("tests", "testthat", "fixtures", "ros")
rng = random.Random(28)
t0 = 1700000000
n_imu = 200
rows = []


def stamp(ns):
    return Time(t0 + ns // 1000000000, ns % 1000000000)


def messages():
    # In receive-time order: IMU every 5 ms, an image every 100 ms.
    ev = [(i * 5000000, 0, i) for i in range(n_imu)]
    ev += [(j * 100000000 + 2500000, 1, j) for j in range(n_imu // 20)]
    for ns, kind, i in sorted(ev):
        if kind == 0:
            m = Imu()
            m.header.seq = i
            m.header.stamp = stamp(ns)
            m.header.frame_id = "imu"
            m.orientation.w = 1.0
            g = [rng.gauss(0, 0.01) for _ in range(3)]
            a = [rng.gauss(0, 0.02) for _ in range(3)]
            a[2] += 9.81
            m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z = g
            m.linear_acceleration.x, m.linear_acceleration.y, m.linear_acceleration.z = a
            rows.append((ns, g, a))
            yield "/imu0", m, stamp(ns + 1000000)
        else:
            m = Image()
            m.header.seq = i
            m.header.stamp = stamp(ns)
            m.header.frame_id = "cam0"
            m.height, m.width, m.encoding, m.step = 24, 32, "mono8", 32
            m.data = bytes(rng.randrange(256) for _ in range(32 * 24))
            yield "/cam0/image_raw", m, stamp(ns + 1000000)


def write(path, compression, cut=None):
    global rng, rows
    rng = random.Random(28)
    rows = []
    bag = rosbag.Bag(path, "w", compression=compression, chunk_threshold=16 * 1024)
    for k, (topic, m, t) in enumerate(messages()):
        bag.write(topic, m, t)
        if cut is not None and k == cut:
            bag._file.flush()
            shutil.copyfile(path, cut_path)
    bag.close()


os.makedirs(out, exist_ok=True)
cut_path = os.path.join(out, "rosbag_unindexed.bag")
write(os.path.join(out, "rosbag_lz4.bag"), "lz4")
write(os.path.join(out, "rosbag_none.bag"), "none", cut=150)
with open(os.path.join(out, "rosbag_imu.csv"), "w") as f:
    f.write("timestamp,omega_x,omega_y,omega_z,alpha_x,alpha_y,alpha_z\n")
    for ns, g, a in rows:
        f.write("%d,%s\n" % (t0 * 1000000000 + ns, ",".join("%.17g" % v for v in g + a)))
