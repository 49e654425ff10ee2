#include "tools/correspondence.h"

#include "mesh/errors.h"
#include "tools/atomic_file.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <initializer_list>

namespace geomip::tools {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& what) { throw InvalidInput(path + ": " + what); }

std::vector<PointSpec> point_list(const std::string& path, const nlohmann::json& list, const std::string& where) {
  std::vector<PointSpec> out;
  if (!list.is_array()) fail(path, where + " must be an array");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const auto& p = list[i];
    PointSpec s;
    if (p.is_number_integer() && p.get<long long>() >= 0) {
      s.index = p.get<long long>();
    } else if (p.is_array() && p.size() == 3 && p[0].is_number() && p[1].is_number() && p[2].is_number()) {
      s.position = {p[0].get<double>(), p[1].get<double>(), p[2].get<double>()};
      if (!s.position.allFinite()) fail(path, where + "[" + std::to_string(i) + "] is not finite");
    } else {
      fail(path, where + "[" + std::to_string(i) + "] must be a vertex index >= 0 or [x,y,z]");
    }
    out.push_back(s);
  }
  return out;
}

// Levenshtein distance of two short keys.
std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

// Keys other than `known` are the user's own (names, notes) and are ignored, unless one looks like a
// misspelling of a known key (differs in case or by at most two edits): that key would be silently lost, so
// it is refused, naming the key it resembles.
void check_keys(const std::string& path, const nlohmann::json& object,
                std::initializer_list<const char*> known, const std::string& where) {
  for (const auto& item : object.items()) {
    const std::string& key = item.key();
    bool exact = false;
    for (const char* k : known) exact = exact || key == k;
    if (exact) continue;
    std::string lower = key;
    for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    for (const char* k : known) {
      if (lower == k || edit_distance(key, k) <= 2)
        fail(path, where + "\"" + key + "\" is not a key geomip reads; did you mean \"" + k + "\"?");
    }
  }
}

std::vector<PointSpec> points(const std::string& path, const nlohmann::json& model, const char* key, std::size_t m) {
  if (!model.contains(key)) return {};
  return point_list(path, model.at(key), "models[" + std::to_string(m) + "]." + key);
}

}  // namespace

std::vector<ModelSpec> read_correspondence(const std::string& path) {
  note_input_file(path);
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) fail(path, "is a directory, not a correspondence file");
  std::ifstream in(path);
  if (!in) fail(path, std::filesystem::exists(path) ? "cannot open for reading" : "no such file");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    fail(path, std::string("not valid JSON: ") + e.what());
  }
  if (j.is_object()) check_keys(path, j, {"models", "layout"}, "");  // "model": said before "no models"
  if (!j.is_object() || !j.contains("models") || !j["models"].is_array() || j["models"].empty()) {
    fail(path, "expected {\"models\": [ ... ]} with at least one model");
  }
  const std::filesystem::path base = std::filesystem::path(path).parent_path();
  std::vector<std::array<int, 4>> quads;
  if (j.contains("layout")) {
    const auto& layout = j["layout"];
    if (!layout.is_object() || !layout.contains("quads") || !layout["quads"].is_array() || layout["quads"].empty())
      fail(path, "\"layout\" must be {\"quads\": [[a,b,c,d], ...]} with at least one quad");
    check_keys(path, layout, {"quads"}, "layout: ");
    for (std::size_t q = 0; q < layout["quads"].size(); ++q) {
      const auto& quad = layout["quads"][q];
      std::array<int, 4> ids{};
      bool ok = quad.is_array() && quad.size() == 4;
      for (std::size_t c = 0; ok && c < 4; ++c) {
        ok = quad[c].is_number_integer() && quad[c].get<long long>() >= 0 && quad[c].get<long long>() < (1LL << 30);
        if (ok) ids[c] = static_cast<int>(quad[c].get<long long>());
      }
      if (!ok) fail(path, "layout.quads[" + std::to_string(q) + "] must be 4 corner indices >= 0");
      quads.push_back(ids);
    }
  }
  std::vector<ModelSpec> models;
  for (std::size_t m = 0; m < j["models"].size(); ++m) {
    const auto& model = j["models"][m];
    if (!model.is_object() || !model.contains("mesh") || !model["mesh"].is_string()) {
      fail(path, "models[" + std::to_string(m) + "] needs a \"mesh\" path");
    }
    check_keys(path, model, {"mesh", "partition_points", "auxiliary_points", "features", "side_guides"},
               "models[" + std::to_string(m) + "]: ");
    ModelSpec s;
    const std::filesystem::path mesh = model["mesh"].get<std::string>();
    s.mesh = (mesh.is_absolute() ? mesh : base / mesh).string();
    s.partition_points = points(path, model, "partition_points", m);
    s.auxiliary_points = points(path, model, "auxiliary_points", m);
    s.features = points(path, model, "features", m);
    if (model.contains("side_guides")) {
      const auto& lists = model.at("side_guides");
      const std::string where = "models[" + std::to_string(m) + "].side_guides";
      if (!lists.is_array() || lists.size() != 4) fail(path, where + " must be 4 lists of points, one per path");
      for (std::size_t k = 0; k < 4; ++k) {
        s.side_guides.push_back(point_list(path, lists[k], where + "[" + std::to_string(k) + "]"));
      }
      if (!s.auxiliary_points.empty()) fail(path, "models[" + std::to_string(m) + "] has both auxiliary_points and side_guides");
      if (!quads.empty()) fail(path, "models[" + std::to_string(m) + "] has side_guides; a layout's paths take no guides");
    }
    s.layout_quads = quads;
    if (!quads.empty()) {
      if (s.partition_points.empty())
        fail(path, "models[" + std::to_string(m) + "] needs partition_points: the layout's corners");
      if (!s.auxiliary_points.empty())
        fail(path, "models[" + std::to_string(m) + "] has auxiliary_points; a layout's paths take no guides");
      if (!models.empty() && s.partition_points.size() != models[0].partition_points.size()) {
        fail(path, "models[" + std::to_string(m) + "] has " + std::to_string(s.partition_points.size()) +
                       " layout corners, models[0] has " + std::to_string(models[0].partition_points.size()));
      }
    } else if (s.partition_points.size() != 4) {
      fail(path, "models[" + std::to_string(m) + "].partition_points must list 4 points, it lists " +
                     std::to_string(s.partition_points.size()));
    }
    if (!models.empty() && s.features.size() != models[0].features.size()) {
      fail(path, "models[" + std::to_string(m) + "] has " + std::to_string(s.features.size()) +
                     " features, models[0] has " + std::to_string(models[0].features.size()) +
                     " (features correspond by order)");
    }
    models.push_back(std::move(s));
  }
  return models;
}

}  // namespace geomip::tools
