// Prints the catalogue as the MeshLab plugin presents it (filter names, parameter ids, Rich
// types, defaults, ranges) as JSON, for the test scripts that write .mlx files and check
// meshlabserver's filter list. Uses the plugin's own mapping (hedge_filters.h).
#include <cstdio>
#include <string>

#include "hedge/catalogue.h"
#include "hedge_filters.h"

int main() {
  using namespace hedge;
  std::string out = "{\"operations\": [";
  bool first_op = true;
  for (const Operation& op : catalogue()) {
    std::string params = "[";
    for (std::size_t i = 0; i < op.params.size(); ++i) {
      const ParamSpec& p = op.params[i];
      JsonObject param = param_json(p);
      param.add("rich_type", meshlab::rich_type_name(meshlab::rich_kind(p)));
      params += (i ? ",\n    " : "\n    ") + param.str();
    }
    JsonObject entry;
    entry.add("id", op.id).add("title", op.title).add("filter", meshlab::filter_name(op).toStdString());
    entry.add("category", category_name(op.category)).add("filter_class", meshlab::filter_class(op));
    entry.add("changes_mesh", op.changes_mesh).raw("params", params + "]");
    out += std::string(first_op ? "" : ",") + "\n  " + entry.str();
    first_op = false;
  }
  out += "\n]}\n";
  std::fputs(out.c_str(), stdout);
  return 0;
}
