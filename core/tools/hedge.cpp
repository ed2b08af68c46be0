// The `hedge` command line: info, convert, and every catalogue operation
// (`hedge OP IN OUT --param value`), generated from the catalogue.
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "hedge/build.h"
#include "hedge/catalogue.h"
#include "hedge/distance.h"
#include "hedge/error.h"
#include "hedge/io.h"
#ifdef HEDGE_HAS_OPENMESH
#include "hedge/openmesh.h"
#endif
#include "hedge/report.h"
#include "hedge/threads.h"
#include "hedge/topology.h"
#include "terminal_progress.h"

namespace {

using namespace hedge;

constexpr const char* kUsage =
    "usage:\n"
    "  hedge info FILE [--json]          counts, topology and what building repaired\n"
    "  hedge convert IN OUT [--ascii]    between OFF, OBJ, PLY, STL and OpenMesh's OM\n"
    "  hedge distance A B [--json] [--samples-per-face N]\n"
    "                                    symmetric Hausdorff distance between two meshes (sampled),\n"
    "                                    and the faces of B turned over against A\n"
    "  hedge list [--json]               every operation with its parameters\n"
    "  hedge help OP                     one operation in full\n"
    "  hedge OP IN [OUT] [--param value ...] [--json] [--ascii] [--quiet]\n"
    "                                    run an operation (OUT not needed for report); on a terminal\n"
    "                                    its stages and a progress bar go to stderr (-q, --quiet: none);\n"
    "                                    Ctrl-C cancels, writes no OUT and exits with 130\n"
    "environment: HEDGE_THREADS=N        threads to use (default: all cores; results never depend on it)\n";

// Files: hedge's own readers and writers, and OpenMesh's .om through OpenMesh's IO when
// hedge was built with OpenMesh (the core library's IO never depends on it).
bool is_om_file(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return extension == ".om";
}

#ifdef HEDGE_HAS_OPENMESH
void warn_skipped(const std::string& path, const std::vector<openmesh::SkippedProperty>& skipped) {
  for (const auto& s : skipped)
    std::fprintf(stderr, "hedge: %s: %s property '%s' not carried: %s\n", path.c_str(), s.where.c_str(), s.name.c_str(),
                 s.reason.c_str());
}
#else
[[noreturn]] void no_openmesh(const std::string& path) {
  throw Error(path + ": .om files need a hedge built with OpenMesh (libopenmesh-dev)");
}
#endif

Soup read_file(const std::string& path) {
  if (!is_om_file(path)) return read_mesh(path);
#ifdef HEDGE_HAS_OPENMESH
  std::vector<openmesh::SkippedProperty> skipped;
  Soup soup = openmesh::read_om(path, &skipped);
  warn_skipped(path, skipped);
  return soup;
#else
  no_openmesh(path);
#endif
}

//! Refuses an output file of unknown format before anything is read.
void check_output_format(const std::string& path) {
  if (!is_om_file(path)) {
    format_from_path(path);
    return;
  }
#ifndef HEDGE_HAS_OPENMESH
  no_openmesh(path);
#endif
}

void write_file(const Soup& soup, const std::string& path, const WriteOptions& options) {
  if (!is_om_file(path)) return write_mesh(soup, path, options);
#ifdef HEDGE_HAS_OPENMESH
  const openmesh::FromSoupReport report = openmesh::write_om(soup, path);
  warn_skipped(path, report.skipped);
  // OpenMesh holds only manifold meshes: say what it took to write every face.
  if (report.vertex_copies)
    std::fprintf(stderr, "hedge: %s: %zu vertices written twice or more so that OpenMesh holds every face\n",
                 path.c_str(), report.vertex_copies);
  if (!report.skipped_faces.empty())
    std::fprintf(stderr, "hedge: %s: %zu faces of fewer than 3 distinct vertices not written\n", path.c_str(),
                 report.skipped_faces.size());
#else
  no_openmesh(path);
#endif
}

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
  return JsonObject()
      .add("non_manifold_edges", r.non_manifold_edges)
      .add("non_manifold_vertices", r.non_manifold_vertices)
      .add("vertex_copies", r.vertex_copies)
      .add("flipped_faces", r.flipped_faces)
      .add("unorientable_edges", r.unorientable_edges)
      .add("repeated_vertex_faces", r.repeated_vertex_faces)
      .add("skipped_faces", r.skipped_faces)
      .add("isolated_vertices", r.isolated_vertices)
      .str();
}

int info(const std::vector<std::string>& args) {
  if (args.empty()) throw Error("info: which file? " + std::string(kUsage));
  bool json = false;
  std::string path;
  for (const auto& a : args) {
    if (a == "--json")
      json = true;
    else if (a.rfind("--", 0) == 0)
      throw Error("info: unknown option " + a);
    else
      path = a;
  }
  Soup soup = read_file(path);
  BuildResult built = build(soup);
  TopologyStats t = topology_stats(built.mesh);
  const BuildReport& r = built.report;
  if (json) {
    const std::string text = JsonObject()
                                 .add("file", path)
                                 .add("vertices", t.vertices)
                                 .add("edges", t.edges)
                                 .add("faces", t.faces)
                                 .add("halfedges", t.halfedges)
                                 .add("boundary_loops", t.boundary_loops)
                                 .add("components", t.components)
                                 .add("euler_characteristic", t.euler_characteristic)
                                 .add("genus", t.genus)
                                 .add("isolated_vertices", t.isolated_vertices)
                                 .raw("repairs", json_repairs(r))
                                 .str();
    std::printf("%s\n", text.c_str());
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
    if (a == "--ascii")
      options.binary = false;
    else if (a.rfind("--", 0) == 0)
      throw Error("convert: unknown option " + a);
    else
      files.push_back(a);
  }
  if (files.size() != 2) throw Error("convert: needs IN and OUT\n" + std::string(kUsage));
  check_output_format(files[1]);  // refuse an unknown output format before reading
  write_file(read_file(files[0]), files[1], options);
  return 0;
}

// `hedge distance A B`: how far two meshes are apart (e.g. a decimated mesh and its input),
// with the same sampler the tests use, relative to A's bounding-box diagonal.
int distance_command(const std::vector<std::string>& args) {
  std::vector<std::string> files;
  bool json = false;
  HausdorffOptions options;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--json") {
      json = true;
    } else if (a == "--samples-per-face") {
      if (i + 1 == args.size()) throw Error("distance: --samples-per-face needs a value");
      const std::string text = args[++i];
      char* end = nullptr;
      options.sample_density = std::strtod(text.c_str(), &end);
      if (end == text.c_str() || *end || !(options.sample_density >= 0 && options.sample_density <= 1000))
        throw Error("distance: --samples-per-face must be a number from 0 to 1000, not '" + text + "'");
    } else if (a.rfind("--", 0) == 0) {
      throw Error("distance: unknown option " + a);
    } else {
      files.push_back(a);
    }
  }
  if (files.size() != 2) throw Error("distance: needs two files, A and B\n" + std::string(kUsage));
  const Mesh a = build(read_file(files[0])).mesh, b = build(read_file(files[1])).mesh;
  if (a.n_faces() == 0 || b.n_faces() == 0) throw Error("distance: " + files[a.n_faces() ? 1 : 0] + " has no faces");
  const double diagonal = mesh_statistics(a).bbox_diagonal;
  const HausdorffResult h = hausdorff(a, b, options);
  const std::size_t flipped = flipped_faces(b, TriangleTree(a));
  const double scale = diagonal > 0 ? 1 / diagonal : 0;
  if (json) {
    auto side = [](const OneSidedDistance& d) {
      return JsonObject().add("max", d.max).add("mean", d.mean).add("rms", d.rms).add("samples", d.samples).str();
    };
    const std::string text = JsonObject()
                                 .add("hausdorff", h.max)
                                 .add("hausdorff_over_diagonal", h.max * scale)
                                 .add("diagonal", diagonal)
                                 .raw("a_to_b", side(h.a_to_b))
                                 .raw("b_to_a", side(h.b_to_a))
                                 .add("faces_a", a.n_faces())
                                 .add("faces_b", b.n_faces())
                                 .add("flipped_faces", flipped)
                                 .str();
    std::printf("%s\n", text.c_str());
    return 0;
  }
  std::printf("A %s: %zu faces; B %s: %zu faces\n", files[0].c_str(), a.n_faces(), files[1].c_str(), b.n_faces());
  std::printf("  symmetric Hausdorff   %.6g (%.6g of A's bounding-box diagonal %.6g)\n", h.max, h.max * scale,
              diagonal);
  std::printf("  A to B                max %.6g, mean %.6g, rms %.6g (%zu samples)\n", h.a_to_b.max, h.a_to_b.mean,
              h.a_to_b.rms, h.a_to_b.samples);
  std::printf("  B to A                max %.6g, mean %.6g, rms %.6g (%zu samples)\n", h.b_to_a.max, h.b_to_a.mean,
              h.b_to_a.rms, h.b_to_a.samples);
  std::printf("  faces of B flipped    %zu (facing away from the nearest part of A)\n", flipped);
  return 0;
}

void print_param(const ParamSpec& p) {
  // A vertex attribute is typed as a name, and its empty default reads "none".
  const bool name = p.type == ParamType::vertex_channel;
  const std::string fallback = name && p.default_text().empty() ? "none" : p.default_text();
  std::printf("    %-24s %-5s default %-8s %s\n", flag_of(p.id).c_str(), name ? "name" : param_type_name(p.type),
              fallback.c_str(), p.range_text().c_str());
}

int list(const std::vector<std::string>& args) {
  for (const auto& a : args)
    if (a != "--json") throw Error("list: unknown option " + a);
  if (!args.empty()) {
    std::fputs(catalogue_json().c_str(), stdout);
    return 0;
  }
  for (const auto& op : catalogue()) {
    std::printf("%-14s %s (%s)\n", op.id.c_str(), op.title.c_str(), category_name(op.category));
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

// Writes beside `path` under a hidden name with its extension (which picks the format), then
// renames: a failed or interrupted (Ctrl-C) write leaves neither a partial file nor a damaged older one.
void write_whole_or_nothing(const Soup& soup, const std::string& path, const WriteOptions& options) {
  const std::filesystem::path out = path;
  const std::string partial =
      (out.parent_path() / ("." + out.stem().string() + ".partial" + out.extension().string())).string();
  const auto discard_partial = [&] {
    std::error_code ignored;
    std::filesystem::remove(partial, ignored);
  };
  try {
    write_file(soup, partial, options);
    if (cli::interrupted()) throw Cancelled();
    std::filesystem::rename(partial, out);
  } catch (const Cancelled&) {
    discard_partial();
    throw;
  } catch (const std::exception& e) {
    discard_partial();
    std::string message = e.what();  // name the file the user asked for, not the hidden one
    if (const auto at = message.find(partial); at != std::string::npos) message.replace(at, partial.size(), path);
    throw Error(message);
  }
}

int run(const std::string& id, const std::vector<std::string>& args) {
  const Operation& op = find_operation(id);
  std::vector<std::string> files;
  std::map<std::string, std::string> given;
  bool json = false, quiet = false;
  WriteOptions options;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--json")
      json = true;
    else if (a == "--ascii")
      options.binary = false;
    else if (a == "--quiet" || a == "-q")
      quiet = true;
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
    throw Error(op.id + ": needs " + (needed == 2 ? "IN and OUT files" : "an IN file") + "; see 'hedge help " + op.id +
                "'");
  ParamValues params = resolve_params(op, given);  // refuse bad parameters before reading anything
  if (op.changes_mesh) check_output_format(files[1]);
  cli::TerminalProgress bar(!quiet);
  const auto file_name = [](const std::string& path) { return std::filesystem::path(path).filename().string(); };
  bar.update(0, "reading " + file_name(files[0]));
  Soup soup = read_file(files[0]);
  if (cli::interrupted()) throw Cancelled();  // reading does not look at the flag itself
  Progress progress([&](double fraction, const std::string& stage) { return bar.update(fraction, stage); });
  RunResult result = run_operation(op, soup, params, progress);
  if (op.changes_mesh) {
    bar.update(1, "writing " + file_name(files[1]));
    write_whole_or_nothing(result.soup, files[1], options);
  }
  bar.finish();
  std::fputs(json ? (result.report.to_json() + "\n").c_str() : result.report.to_text().c_str(), stdout);
  return 0;
}

//! HEDGE_THREADS: a whole number from 1 to 1024; unset or empty means every core.
void apply_thread_setting() {
  const char* text = std::getenv("HEDGE_THREADS");
  if (!text || !*text) return;
  char* end = nullptr;
  errno = 0;
  const unsigned long n = std::strtoul(text, &end, 10);
  if (errno || *end || n < 1 || n > 1024 || *text == '-' || *text == '+' || *text == ' ')
    throw Error(std::string("HEDGE_THREADS must be a whole number from 1 to 1024, not '") + text + "'");
  set_thread_count(static_cast<unsigned>(n));
}

// This process is hedge's own, unlike the hosts' (whose allocator settings the core leaves
// alone): every block comes from the heap, which keeps what is freed until the process ends,
// so the memory one stage frees serves the next instead of fresh pages from the kernel.
// glibc otherwise maps large blocks afresh (above 128 KiB at first, 32 MiB at most) and
// unmaps them when they are freed.
void reuse_freed_memory() {
#ifdef __GLIBC__
  mallopt(M_MMAP_MAX, 0);
  mallopt(M_TRIM_THRESHOLD, -1);
#endif
}

}  // namespace

int main(int argc, char** argv) {
  reuse_freed_memory();
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h") {
    std::fputs(kUsage, args.empty() ? stderr : stdout);
    return args.empty() ? 2 : 0;
  }
  const std::string command = args[0];
  args.erase(args.begin());
  try {
    apply_thread_setting();
    if (command == "info") return info(args);
    if (command == "convert") return convert(args);
    if (command == "distance") return distance_command(args);
    if (command == "list") return list(args);
    if (command == "help") return help(args);
    cli::install_interrupt_handler();
    return run(command, args);
  } catch (const Cancelled& e) {
    std::fprintf(stderr, "hedge: %s\n", e.what());
    return 130;  // what shells report for a process ended by SIGINT
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hedge: %s\n", e.what());
    return 1;
  }
}
