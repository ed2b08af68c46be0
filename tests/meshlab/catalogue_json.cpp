// Prints the catalogue as the MeshLab plugin presents it (filter names, parameter ids, Rich
// types, defaults, ranges) as JSON, for the test scripts that write .mlx files and check
// meshlabserver's filter list. Uses the plugin's own mapping (hedge_filters.h).
#include <cstdio>
#include <string>

#include "hedge/catalogue.h"
#include "hedge_filters.h"

namespace {

std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) < 0x20) {
      char buffer[8];
      std::snprintf(buffer, sizeof buffer, "\\u%04x", c);
      out += buffer;
      continue;
    }
    out += c;
  }
  return out + "\"";
}

std::string number(double x) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", x);
  return buffer;
}

}  // namespace

int main() {
  using namespace hedge;
  std::string out = "{\"operations\": [";
  bool first_op = true;
  for (const Operation& op : catalogue()) {
    out += std::string(first_op ? "" : ",") + "\n  {\"id\": " + quoted(op.id) + ", \"title\": " + quoted(op.title) +
           ", \"filter\": " + quoted(meshlab::filter_name(op).toStdString()) +
           ", \"category\": " + quoted(op.category) +
           ", \"filter_class\": " + std::to_string(meshlab::filter_class(op)) +
           ", \"changes_mesh\": " + (op.changes_mesh ? "true" : "false") + ", \"params\": [";
    first_op = false;
    bool first_param = true;
    for (const ParamSpec& p : op.params) {
      out += std::string(first_param ? "" : ",") + "\n    {\"id\": " + quoted(p.id) +
             ", \"label\": " + quoted(p.label) + ", \"type\": " + quoted(param_type_name(p.type)) +
             ", \"rich_type\": " + quoted(meshlab::rich_type_name(meshlab::rich_kind(p))) +
             ", \"default\": " + number(p.default_value) + ", \"min\": " + number(p.min) +
             ", \"max\": " + number(p.max) + ", \"choices\": [";
      first_param = false;
      for (std::size_t i = 0; i < p.choices.size(); ++i) out += (i ? ", " : "") + quoted(p.choices[i]);
      out += "]}";
    }
    out += "]}";
  }
  out += "\n]}\n";
  std::fputs(out.c_str(), stdout);
  return 0;
}
