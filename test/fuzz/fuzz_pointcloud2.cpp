// The PointCloud2 converter, as a careless or hostile publisher would fill the message:
// layout (height, width, point_step, row_step, endianness) and up to four fields (name,
// offset, datatype, count) come from the input, the rest is the data buffer. The node
// must never read outside the buffer, whatever the layout claims.
#include <cstring>

#include "breast_tumour_registration/ros/converters.h"
#include "fuzz_common.h"

namespace {
struct Reader {
  const uint8_t* p;
  size_t n;
  template <class T>
  T take() {
    T v{};
    const size_t k = std::min(sizeof(T), n);
    std::memcpy(&v, p, k);
    p += k;
    n -= k;
    return v;
  }
};
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  Reader in{data, size};
  sensor_msgs::PointCloud2 msg;
  msg.height = in.take<uint16_t>();  // 16 bits: layouts up to 65535 rows, so that claims can be large
  msg.width = in.take<uint16_t>();
  msg.point_step = in.take<uint32_t>();
  msg.row_step = in.take<uint32_t>();
  const uint8_t flags = in.take<uint8_t>();
  msg.is_bigendian = flags & 1;
  msg.is_dense = flags & 2;
  const int nfields = in.take<uint8_t>() % 5;
  static const char* kNames[] = {"x", "y", "z", "rgb", "intensity", ""};
  for (int i = 0; i < nfields; ++i) {
    sensor_msgs::PointField f;
    f.name = kNames[in.take<uint8_t>() % 6];
    f.offset = in.take<uint32_t>();
    f.datatype = in.take<uint8_t>();
    f.count = in.take<uint8_t>();
    msg.fields.push_back(f);
  }
  msg.data.assign(in.p, in.p + in.n);
  msg.header.frame_id = "camera";
  for (const bool keep_nan : {false, true})
    btr::fuzz::expect_contract([&] { btr::ros_conv::from_cloud(msg, keep_nan); });
  return 0;
}
