#include "breast_tumour_registration/io/markups_io.h"


#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/strings.h"

namespace btr {
namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r\n") - b + 1);
}

double length_unit(const std::string& path, const std::string& units) {
  const std::string u = lower_case(units);
  if (u.empty() || u == "mm") return 1e-3;
  if (u == "m") return 1.0;
  throw InputError(path + ": coordinate units '" + units + "' (expected mm or m)");
}

PatientFrame frame_of(const std::string& path, const std::string& system) {
  const std::string s = trim(system);
  if (s == "0") return PatientFrame::RAS;  // the numeric codes of Slicer 4.x .fcsv files
  if (s == "1") return PatientFrame::LPS;
  try {
    return parse_patient_frame(s, path);
  } catch (const InputError&) {
    throw InputError(path + ": coordinate system '" + s + "' (expected LPS or RAS)");
  }
}

void check_points(const std::string& path, const std::vector<NamedPoint>& pts) {
  if (pts.empty()) throw InputError(path + ": the point list has no defined points");
  std::set<std::string> seen;
  for (const auto& p : pts) {
    if (p.label.empty()) throw InputError(path + ": a point has no label (points are matched by label)");
    if (!seen.insert(p.label).second) throw InputError(path + ": label '" + p.label + "' is used twice (points are matched by label)");
    if (!p.position.allFinite()) throw InputError(path + ": point '" + p.label + "' has a position that is not a number");
  }
}

std::vector<NamedPoint> read_json(const std::string& path, PatientFrame frame) {
  std::ifstream in(path);
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path + ": not valid JSON (" + std::string(e.what()) + ")");
  }
  if (!j.is_object() || !j.contains("markups") || !j["markups"].is_array() || j["markups"].empty())
    throw InputError(path + ": no 'markups' list (is this a Slicer markups file?)");
  const auto& m = j["markups"][0];
  if (!m.is_object() || !m.contains("controlPoints") || !m["controlPoints"].is_array())
    throw InputError(path + ": the first markup has no 'controlPoints'");
  try {
    const PatientFrame file_frame = frame_of(path, m.value("coordinateSystem", std::string("LPS")));
    const double unit = length_unit(path, m.value("coordinateUnits", std::string("mm")));
    std::vector<NamedPoint> pts;
    for (const auto& cp : m["controlPoints"]) {
      const std::string status = cp.value("positionStatus", std::string("defined"));
      if (status != "defined" && status != "preview") continue;
      if (!cp.contains("position") || !cp["position"].is_array() || cp["position"].size() != 3)
        throw InputError(path + ": control point '" + cp.value("label", std::string()) + "' has no 3-D position");
      NamedPoint p;
      p.label = cp.value("label", std::string());
      const Vec3 x(cp["position"][0].get<double>(), cp["position"][1].get<double>(), cp["position"][2].get<double>());
      p.position = convert_patient_frame(x * unit, file_frame, frame);
      pts.push_back(p);
    }
    check_points(path, pts);
    return pts;
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path + ": unexpected markups content (" + std::string(e.what()) + ")");
  }
}

// One CSV line, with Slicer's quoting of fields that contain commas.
std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (c == '"') {
      if (quoted && i + 1 < line.size() && line[i + 1] == '"') cur += '"', ++i;
      else quoted = !quoted;
    } else if (c == ',' && !quoted) {
      out.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  out.push_back(cur);
  return out;
}

double number(const std::string& path, int line, const std::string& field) {
  const std::string s = trim(field);
  const auto x = parse_number(s);
  if (!x) throw InputError(path + ":" + std::to_string(line) + ": '" + s + "' is not a number");
  return *x;
}

std::vector<NamedPoint> read_fcsv(const std::string& path, PatientFrame frame) {
  std::ifstream in(path);
  PatientFrame file_frame = PatientFrame::RAS;  // Slicer before 4.11 wrote RAS without saying so
  std::vector<std::string> columns = {"id", "x", "y", "z", "ow", "ox", "oy", "oz", "vis", "sel", "lock", "label"};
  std::vector<NamedPoint> pts;
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    const std::string t = trim(line);
    if (t.empty()) continue;
    if (t[0] == '#') {
      const auto eq = t.find('=');
      if (eq == std::string::npos) continue;
      const std::string key = lower_case(trim(t.substr(1, eq - 1))), value = trim(t.substr(eq + 1));
      if (key == "coordinatesystem") file_frame = frame_of(path, value);
      if (key == "columns") {
        columns = split_csv(value);
        for (auto& c : columns) c = lower_case(trim(c));
      }
      continue;
    }
    const auto f = split_csv(t);
    auto col = [&](const std::string& name) {
      for (size_t i = 0; i < columns.size(); ++i)
        if (columns[i] == name) return i < f.size() ? trim(f[i]) : std::string();
      throw InputError(path + ": no '" + name + "' column");
    };
    NamedPoint p;
    p.label = col("label");
    const Vec3 x(number(path, n, col("x")), number(path, n, col("y")), number(path, n, col("z")));
    p.position = convert_patient_frame(x * 1e-3, file_frame, frame);
    pts.push_back(p);
  }
  check_points(path, pts);
  return pts;
}

}  // namespace

std::vector<NamedPoint> read_markups(const std::string& path, PatientFrame frame) {
  if (!std::filesystem::exists(path)) throw InputError(path + ": no such file");
  const std::string p = lower_case(path);
  if (ends_with(p, ".json")) return read_json(path, frame);
  if (ends_with(p, ".fcsv")) return read_fcsv(path, frame);
  throw InputError(path + ": unknown markups format (expected .mrk.json or .fcsv)");
}

void write_markups(const std::string& path, const std::vector<NamedPoint>& points, PatientFrame points_frame,
                   PatientFrame file_frame, const std::vector<std::string>& descriptions) {
  nlohmann::json cps = nlohmann::json::array();
  for (size_t i = 0; i < points.size(); ++i) {
    const Vec3 x = convert_patient_frame(points[i].position, points_frame, file_frame) * 1e3;
    cps.push_back({{"id", std::to_string(i + 1)},
                   {"label", points[i].label},
                   {"description", i < descriptions.size() ? descriptions[i] : std::string()},
                   {"position", {x[0], x[1], x[2]}},
                   {"positionStatus", "defined"},
                   {"selected", true},
                   {"locked", false},
                   {"visibility", true}});
  }
  const nlohmann::json j = {
      {"@schema", "https://raw.githubusercontent.com/slicer/slicer/master/Modules/Loadable/Markups/Resources/Schema/markups-schema-v1.0.3.json#"},
      {"markups", {{{"type", "Fiducial"}, {"coordinateSystem", to_string(file_frame)}, {"coordinateUnits", "mm"}, {"controlPoints", cps}}}}};
  std::ofstream out(path);
  if (!out) throw InputError(path + ": cannot be written");
  out << j.dump(2) << "\n";
}

MatchedPoints match_by_label(const std::vector<NamedPoint>& first, const std::vector<NamedPoint>& second) {
  std::map<std::string, Vec3> by_label;
  for (const auto& p : second) by_label[p.label] = p.position;
  MatchedPoints m;
  std::vector<Vec3> a, b;
  std::set<std::string> used;
  for (const auto& p : first) {
    auto it = by_label.find(p.label);
    if (it == by_label.end()) {
      m.unmatched.push_back(p.label);
      continue;
    }
    m.labels.push_back(p.label);
    a.push_back(p.position);
    b.push_back(it->second);
    used.insert(p.label);
  }
  for (const auto& p : second)
    if (!used.count(p.label)) m.unmatched.push_back(p.label);
  m.first.resize(static_cast<Eigen::Index>(a.size()), 3);
  m.second.resize(static_cast<Eigen::Index>(b.size()), 3);
  for (size_t i = 0; i < a.size(); ++i) {
    m.first.row(static_cast<Eigen::Index>(i)) = a[i].transpose();
    m.second.row(static_cast<Eigen::Index>(i)) = b[i].transpose();
  }
  return m;
}

}  // namespace btr
