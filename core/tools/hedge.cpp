// The `hedge` command line: info, convert, and every catalogue operation
// (`hedge OP IN OUT --param value`), generated from the catalogue.
#include <cstdio>
#include <cstring>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "hedge/build.h"
#include "hedge/catalogue.h"
#include "hedge/error.h"
#include "hedge/io.h"
#include "hedge/topology.h"

namespace {

using namespace hedge;

constexpr const char* kUsage =
    "usage:\n"
    "  hedge info FILE [--json]          counts, topology and what building repaired\n"
    "  hedge convert IN OUT [--ascii]    between OFF, OBJ, PLY and STL\n"
    "  hedge list                        every operation with its parameters\n"
    "  hedge help OP                     one operation in full\n"
    "  hedge OP IN [OUT] [--param value ...] [--json] [--ascii]\n"
    "                                    run an operation (OUT not needed for report)\n";

std::string flag_of(const std::string& id) {
  std::string flag = "--" + id;
  for (char& c : flag)
    if (c == '_') c = '-';
  return flag;
}

std::string id_of(const std::string& flag) {
  std::string id = flag.substr(2);
  for (char& c : id)
    if (c == '-') c = '_';
  return id;
}

std::string json_repairs(const BuildReport& r) {
  auto n = [](std::size_t x) { return std::to_string(x); };
  return "{\"non_manifold_edges\": " + n(r.non_manifold_edges) + ", \"non_manifold_vertices\": " +
         n(r.non_manifold_vertices) + ", \"vertex_copies\": " + n(r.vertex_copies) + ", \"flipped_faces\": " +
         n(r.flipped_faces) + ", \"unorientable_edges\": " + n(r.unorientable_edges) +
         ", \"repeated_vertex_faces\": " + n(r.repeated_vertex_faces) + ", \"skipped_faces\": " + n(r.skipped_faces) +
         ", \"isolated_vertices\": " + n(r.isolated_vertices) + "}";
}

int info(const std::vector<std::string>& args) {
  if (args.empty()) throw Error("info: which file? " + std::string(kUsage));
  bool json = false;
  std::string path;
  for (const auto& a : args) {
    if (a == "--json") json = true;
    else if (a.rfind("--", 0) == 0) throw Error("info: unknown option " + a);
    else path = a;
  }
  Soup soup = read_mesh(path);
  BuildResult built = build(soup);
  TopologyStats t = topology_stats(built.mesh);
  const BuildReport& r = built.report;
  if (json) {
    std::printf(
        "{\"file\": \"%s\", \"vertices\": %zu, \"edges\": %zu, \"faces\": %zu, \"halfedges\": %zu, "
        "\"boundary_loops\": %zu, \"components\": %zu, \"euler_characteristic\": %lld, \"genus\": %lld, "
        "\"isolated_vertices\": %zu, \"repairs\": %s}\n",
        path.c_str(), t.vertices, t.edges, t.faces, t.halfedges, t.boundary_loops, t.components,
        static_cast<long long>(t.euler_characteristic), static_cast<long long>(t.genus), t.isolated_vertices,
        json_repairs(r).c_str());
    return 0;
  }
  std::printf("%s\n", path.c_str());
  std::printf("  vertices              %zu (file: %zu)\n", t.vertices, soup.n_vertices());
  std::printf("  edges                 %zu\n", t.edges);
  std::printf("  faces                 %zu (file: %zu)\n", t.faces, soup.n_faces());
  std::printf("  half-edges            %zu\n", t.halfedges);
  std::printf("  boundary loops        %zu\n", t.boundary_loops);
  std::printf("  components            %zu\n", t.components);
  std::printf("  Euler characteristic  %lld\n", static_cast<long long>(t.euler_characteristic));
  std::printf("  genus                 %lld\n", static_cast<long long>(t.genus));
  std::printf("  isolated vertices     %zu\n", t.isolated_vertices);
  for (const auto& c : soup.channels)
    std::printf("  attribute             %s (%s, %d x %s)\n", c.name.c_str(), domain_name(c.domain), c.components,
                scalar_name(c.scalar));
  if (r.messages.empty()) std::printf("  repairs               none\n");
  for (const auto& m : r.messages) std::printf("  repaired              %s\n", m.c_str());
  return 0;
}

int convert(const std::vector<std::string>& args) {
  std::vector<std::string> files;
  WriteOptions options;
  for (const auto& a : args) {
    if (a == "--ascii") options.binary = false;
    else if (a.rfind("--", 0) == 0) throw Error("convert: unknown option " + a);
    else files.push_back(a);
  }
  if (files.size() != 2) throw Error("convert: needs IN and OUT\n" + std::string(kUsage));
  format_from_path(files[1]);  // refuse an unknown output format before reading
  write_mesh(read_mesh(files[0]), files[1], options);
  return 0;
}

void print_param(const ParamSpec& p) {
  std::printf("    %-24s %-5s default %-8s %s\n", flag_of(p.id).c_str(), param_type_name(p.type), p.default_text().c_str(),
              p.range_text().c_str());
}

int list() {
  for (const auto& op : catalogue()) {
    std::printf("%-14s %s (%s)\n", op.id.c_str(), op.title.c_str(), op.category.c_str());
    for (const auto& p : op.params) print_param(p);
  }
  return 0;
}

int help(const std::vector<std::string>& args) {
  if (args.size() != 1) throw Error("help: which operation? see 'hedge list'");
  const Operation& op = find_operation(args[0]);
  std::printf("hedge %s IN%s [options]\n\n%s\n\n%s\n", op.id.c_str(), op.changes_mesh ? " OUT" : "", op.title.c_str(),
              op.help.c_str());
  if (!op.params.empty()) std::printf("\noptions:\n");
  for (const auto& p : op.params) {
    print_param(p);
    std::printf("        %s\n", p.help.c_str());
  }
  return 0;
}

int run(const std::string& id, const std::vector<std::string>& args) {
  const Operation& op = find_operation(id);
  std::vector<std::string> files;
  std::map<std::string, std::string> given;
  bool json = false;
  WriteOptions options;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--json") json = true;
    else if (a == "--ascii") options.binary = false;
    else if (a.rfind("--", 0) == 0) {
      std::string key = a, value;
      if (auto eq = a.find('='); eq != std::string::npos) {
        key = a.substr(0, eq);
        value = a.substr(eq + 1);
      } else if (i + 1 < args.size()) {
        value = args[++i];
      } else {
        throw Error(op.id + ": " + a + " needs a value");
      }
      given[id_of(key)] = value;
    } else {
      files.push_back(a);
    }
  }
  const std::size_t needed = op.changes_mesh ? 2 : 1;
  if (files.size() != needed && !(files.size() == 2 && !op.changes_mesh))
    throw Error(op.id + ": needs " + (needed == 2 ? "IN and OUT files" : "an IN file") + "; see 'hedge help " + op.id + "'");
  ParamValues params = resolve_params(op, given);  // refuse bad parameters before reading anything
  if (op.changes_mesh) format_from_path(files[1]);
  Soup soup = read_mesh(files[0]);
  RunResult result = run_operation(op, soup, params, Progress::none());
  if (op.changes_mesh) write_mesh(result.soup, files[1], options);
  std::fputs(json ? (result.report.to_json() + "\n").c_str() : result.report.to_text().c_str(), stdout);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h") {
    std::fputs(kUsage, args.empty() ? stderr : stdout);
    return args.empty() ? 2 : 0;
  }
  const std::string command = args[0];
  args.erase(args.begin());
  try {
    if (command == "info") return info(args);
    if (command == "convert") return convert(args);
    if (command == "list") return list();
    if (command == "help") return help(args);
    return run(command, args);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hedge: %s\n", e.what());
    return 1;
  }
}
