// sensor_msgs/Imu decoders: ROS1 serialization and CDR (ROS2).
#ifndef ALLANVAR_ROS_MSGS_H
#define ALLANVAR_ROS_MSGS_H

#include <cstddef>
#include <cstdint>
#include <vector>

namespace allanvar {

enum msg_encoding { ENC_ROS1 = 0, ENC_CDR = 1 };

// Columns of the decoded table, one row per message.
const int kImuCols = 10;  // sec, nsec, wx, wy, wz, ax, ay, az, recv_sec, recv_nsec

// Appends one row (header stamp, angular velocity, linear acceleration,
// receive time) to `out`; false when the message is too short or malformed.
bool decode_imu(const unsigned char* p, std::size_t n, int encoding,
                std::int64_t recv_ns, std::vector<double>& out);

}  // namespace allanvar

#endif
