#include "breast_tumour_registration/geometry/label_volume.h"

#include <algorithm>
#include <cctype>

#include "breast_tumour_registration/base/errors.h"

namespace btr {

const char* to_string(PatientFrame f) { return f == PatientFrame::RAS ? "RAS" : "LPS"; }

PatientFrame parse_patient_frame(const std::string& s, const std::string& what) {
  std::string u = s;
  std::transform(u.begin(), u.end(), u.begin(), [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  if (u == "RAS") return PatientFrame::RAS;
  if (u == "LPS") return PatientFrame::LPS;
  throw InputError(what + ": patient frame '" + s + "' is neither RAS nor LPS");
}

Vec3 convert_patient_frame(const Vec3& p, PatientFrame from, PatientFrame to) {
  return from == to ? p : Vec3(-p.x(), -p.y(), p.z());
}

std::vector<long> label_histogram(const LabelVolume& v) {
  std::vector<long> h(256, 0);
  for (std::uint8_t l : v.labels) ++h[l];
  return h;
}

}  // namespace btr
