// Conversions of library results to the JSON and text that commands print.
#pragma once

#include "mesh/mesh_topology.h"

#include <nlohmann/json.hpp>

#include <string>

namespace geomip::tools {

/// The keys of `geomip info --json` (genus is null when undefined).
nlohmann::json topology_to_json(const TopologyReport& report);

/// Human-readable multi-line form of the same report.
std::string topology_to_text(const TopologyReport& report);

/// printf() into a string, of any length: the lines a command prints only once its files are in place.
std::string string_printf(const char* format, ...) __attribute__((format(printf, 1, 2)));

}  // namespace geomip::tools
