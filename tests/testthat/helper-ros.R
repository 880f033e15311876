# The ROS fixtures: one recording (/imu0, 300 messages at 200 Hz) written as
# Kalibr CSV, ROS1 bags (none, bz2, lz4 chunks), MCAP (none, lz4, zstd
# chunks; CDR, and ROS1 messages in lz4), and rosbag2 db3, by
# tools/make-bag-fixtures.R from the formats' specifications.
ros_fixture <- function(name) test_path("fixtures", "ros", name)
