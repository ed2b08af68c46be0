// hedge_bench --ops: whole operations (decimate, remesh, Loop, Catmull-Clark and sqrt3
// subdivision, Laplace smoothing) of hedge next to OpenMesh and CGAL in this process, and with --hosts
// next to MeshLab's own filters (meshlabserver) and Blender's Decimate modifier (blender -b)
// as separate processes. One table: times, ratios peer/hedge, result sizes, and for the
// operations that keep the surface, the symmetric Hausdorff distance to the input.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "bench.h"
#include "hedge/build.h"
#include "hedge/distance.h"
#include "hedge/error.h"
#include "hedge/io.h"
#include "hedge/report.h"

namespace bench {

namespace {

namespace fs = std::filesystem;

//! One row of the table: one library's run(s) of one operation.
struct Row {
  Row(std::string op_, std::string library_, std::string scope_)
      : op(std::move(op_)), library(std::move(library_)), scope(std::move(scope_)) {}
  std::string op, library, scope;
  double wall_s = NAN, cpu_s = NAN;  //!< fastest of the repetitions (CPU: NAN for hosts)
  std::size_t faces = 0;
  double hausdorff = NAN;  //!< symmetric, / bounding-box diagonal of the input
  double in_band = NAN;    //!< remesh: edges within [0.8, 1.33] x target
  hedge::MeshStatistics stats;
  bool has_stats = false;
  std::string error;
};

//! What the error columns compare against: the input, built once.
struct Reference {
  hedge::Mesh mesh;
  double diagonal = 0;
  double target_length = 0;  //!< mean edge length of the input (the remeshing target)
  hedge::MeshStatistics stats;
};

bool keeps_surface(const std::string& op) { return op == kOpDecimate || op == kOpRemesh; }

//! Fills the result columns of a row from a library's output soup.
void measure(Row& row, const hedge::Soup& output, const Reference& ref) {
  row.faces = output.n_faces();
  if (!keeps_surface(row.op) || output.n_faces() == 0) return;
  hedge::Mesh mesh = hedge::build(output).mesh;
  hedge::HausdorffOptions options;
  options.sample_density = 1;  // ~1 sample per face of each mesh, plus every vertex and edge midpoint
  row.hausdorff = hedge::hausdorff(ref.mesh, mesh, options).max / ref.diagonal;
  if (row.op == kOpRemesh) {
    std::size_t in = 0;
    for (hedge::Edge e : mesh.edges()) {
      const double l = hedge::distance(hedge::to_double(mesh.position(mesh.vertex(e, 0))),
                                       hedge::to_double(mesh.position(mesh.vertex(e, 1))));
      in += l >= 0.8 * ref.target_length && l <= 1.33 * ref.target_length;
    }
    row.in_band = static_cast<double>(in) / static_cast<double>(std::max<std::size_t>(1, mesh.n_edges()));
    row.stats = hedge::mesh_statistics(mesh);
    row.has_stats = true;
  }
}

// One library's row of an operation while its runs are under way.
struct Contender {
  const OpEntry* entry;
  Row row;
  OpRun last;
};

// Runs every library once per round, in turn, `reps` rounds, so that a machine whose speed
// drifts (a shared VM) slows every library alike; each row keeps its fastest run.
void run_rounds(std::vector<Contender>& contenders, int reps, const Reference& ref) {
  for (int r = 0; r < reps; ++r) {
    for (Contender& c : contenders) {
      if (!c.row.error.empty()) continue;
      std::fprintf(stderr, "  %-9s %-22s round %d/%d", c.entry->op.c_str(), c.row.library.c_str(), r + 1, reps);
      try {
        OpRun run = c.entry->run(ref.target_length);
        c.row.wall_s = std::isnan(c.row.wall_s) ? run.wall_s : std::min(c.row.wall_s, run.wall_s);
        c.row.cpu_s = std::isnan(c.row.cpu_s) ? run.cpu_s : std::min(c.row.cpu_s, run.cpu_s);
        c.last = std::move(run);
        std::fprintf(stderr, " %8.3f s\n", c.last.wall_s);
      } catch (const std::exception& e) {
        c.row.error = e.what();
        std::fprintf(stderr, " failed: %s\n", e.what());
      }
    }
  }
}

// ---- the hosts, as separate processes ------------------------------------------------------

std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string fmt(double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", x);
  return buf;
}

//! A MeshLab filter as an .mlx <filter> element (every parameter with its Rich type, as
//! meshlabserver 2020.09 requires).
struct MlxParam {
  std::string type, name, value, extra;
};
std::string mlx(const std::string& filter, const std::vector<MlxParam>& params) {
  std::string s = "<!DOCTYPE FilterScript>\n<FilterScript>\n <filter name=\"" + filter + "\">\n";
  for (const MlxParam& p : params)
    s += "  <Param type=\"" + p.type + "\" name=\"" + p.name + "\" value=\"" + p.value + "\" description=\"" + p.name +
         "\" tooltip=\"\"" + (p.extra.empty() ? "" : " " + p.extra) + "/>\n";
  return s + " </filter>\n</FilterScript>\n";
}

struct MeshLabCase {
  std::string op, filter, script;
};

std::vector<MeshLabCase> meshlab_cases(const Reference& ref, std::size_t input_faces) {
  const std::string absperc = "min=\"0\" max=\"" + fmt(ref.diagonal) + "\"";
  const auto target_faces = static_cast<long long>(std::llround(kDecimateRatio * static_cast<double>(input_faces)));
  std::vector<MeshLabCase> cases;
  cases.push_back({kOpDecimate, "Simplification: Quadric Edge Collapse Decimation",
                   mlx("Simplification: Quadric Edge Collapse Decimation",
                       {{"RichInt", "TargetFaceNum", std::to_string(target_faces), ""},
                        {"RichFloat", "TargetPerc", "0", ""},
                        {"RichFloat", "QualityThr", "0.3", ""},
                        {"RichBool", "PreserveBoundary", "false", ""},
                        {"RichFloat", "BoundaryWeight", "1", ""},
                        {"RichBool", "PreserveNormal", "false", ""},
                        {"RichBool", "PreserveTopology", "false", ""},
                        {"RichBool", "OptimalPlacement", "true", ""},
                        {"RichBool", "PlanarQuadric", "false", ""},
                        {"RichFloat", "PlanarWeight", "0.001", ""},
                        {"RichBool", "QualityWeight", "false", ""},
                        {"RichBool", "AutoClean", "true", ""},
                        {"RichBool", "Selected", "false", ""}})});
  cases.push_back(
      {kOpRemesh, "Remeshing: Isotropic Explicit Remeshing",
       mlx("Remeshing: Isotropic Explicit Remeshing", {{"RichInt", "Iterations", std::to_string(kRemeshIterations), ""},
                                                       {"RichBool", "Adaptive", "false", ""},
                                                       {"RichBool", "SelectedOnly", "false", ""},
                                                       {"RichAbsPerc", "TargetLen", fmt(ref.target_length), absperc},
                                                       {"RichFloat", "FeatureDeg", "45", ""},
                                                       {"RichBool", "CheckSurfDist", "false", ""},
                                                       {"RichAbsPerc", "MaxSurfDist", fmt(ref.target_length), absperc},
                                                       {"RichBool", "SplitFlag", "true", ""},
                                                       {"RichBool", "CollapseFlag", "true", ""},
                                                       {"RichBool", "SwapFlag", "true", ""},
                                                       {"RichBool", "SmoothFlag", "true", ""},
                                                       {"RichBool", "ReprojectFlag", "true", ""}})});
  cases.push_back(
      {kOpLoop, "Subdivision Surfaces: Loop",
       mlx("Subdivision Surfaces: Loop", {{"RichEnum", "LoopWeight", "0",
                                           "enum_cardinality=\"3\" enum_val0=\"Loop\" enum_val1=\"Enhance regularity\" "
                                           "enum_val2=\"Enhance continuity\""},
                                          {"RichInt", "Iterations", "1", ""},
                                          {"RichAbsPerc", "Threshold", "0", absperc},
                                          {"RichBool", "Selected", "false", ""}})});
  cases.push_back({kOpSmooth, "Laplacian Smooth",
                   mlx("Laplacian Smooth", {{"RichInt", "stepSmoothNum", std::to_string(kSmoothIterations), ""},
                                            {"RichBool", "Boundary", "true", ""},
                                            {"RichBool", "cotangentWeight", "false", ""},
                                            {"RichBool", "Selected", "false", ""}})});
  return cases;
}

//! Reads "name seconds" lines.
std::map<std::string, double> read_times(const fs::path& file) {
  std::map<std::string, double> times;
  std::ifstream in(file);
  std::string name;
  double t;
  while (in >> name >> t) times[name] = t;
  return times;
}

//! MeshLab's filters through meshlabserver, under one Xvfb. The filter's time is what is left
//! of the process's wall clock after taking off loading the input (a run that only loads it)
//! and saving the result (a run that loads and saves the result, minus one that only loads it).
std::vector<Row> run_meshlab(const fs::path& dir, const fs::path& input_ply, const Reference& ref,
                             std::size_t input_faces) {
  std::vector<Row> rows;
  const auto cases = meshlab_cases(ref, input_faces);
  const fs::path home = dir / "home", times = dir / "meshlab_times.txt";
  fs::create_directories(home);
  std::string sh = "set -u\nexport HOME=" + quote(home.string()) + " XDG_RUNTIME_DIR=" + quote(home.string()) +
                   "\nunset QT_QPA_PLATFORM\n: > " + quote(times.string()) + "\n" +
                   "t() { name=$1; shift; s=$(date +%s.%N); meshlabserver \"$@\" > " + quote((dir / "ml_").string()) +
                   "$name.log 2>&1; e=$(date +%s.%N); awk -v n=$name -v s=$s -v e=$e 'BEGIN { print n, e - s }' >> " +
                   quote(times.string()) + "; }\n" + "t load_input -i " + quote(input_ply.string()) + "\n";
  for (const MeshLabCase& c : cases) {
    const fs::path script = dir / ("ml_" + c.op + ".mlx"), out = dir / ("ml_" + c.op + ".ply");
    std::ofstream(script) << c.script;
    sh += "t " + c.op + " -i " + quote(input_ply.string()) + " -o " + quote(out.string()) + " -s " +
          quote(script.string()) + "\n";
    sh += "t load_" + c.op + " -i " + quote(out.string()) + "\n";
    sh += "t save_" + c.op + " -i " + quote(out.string()) + " -o " +
          quote((dir / ("ml_" + c.op + "_again.ply")).string()) + "\n";
  }
  std::ofstream(dir / "meshlab.sh") << sh;
  std::fprintf(stderr, "  MeshLab: meshlabserver, %zu filters (xvfb-run)...\n", cases.size());
  const std::string command = "xvfb-run -a -s '-screen 0 1024x768x24' sh " + quote((dir / "meshlab.sh").string());
  if (std::system(command.c_str()) != 0) std::fprintf(stderr, "  MeshLab: the script did not finish cleanly\n");
  const auto t = read_times(times);
  for (const MeshLabCase& c : cases) {
    Row row{c.op, "MeshLab",
            "meshlabserver '" + c.filter + "': process time - load input - (load+save output - load output)"};
    const fs::path out = dir / ("ml_" + c.op + ".ply");
    if (!t.count(c.op) || !t.count("load_input") || !t.count("load_" + c.op) || !t.count("save_" + c.op) ||
        !fs::exists(out)) {
      row.error = "meshlabserver gave no result (see " + (dir / ("ml_" + c.op + ".log")).string() + ")";
      rows.push_back(row);
      continue;
    }
    row.wall_s = t.at(c.op) - t.at("load_input") - (t.at("save_" + c.op) - t.at("load_" + c.op));
    try {
      measure(row, hedge::read_mesh(out.string()), ref);
    } catch (const std::exception& e) {
      row.error = std::string("cannot read MeshLab's result: ") + e.what();
    }
    std::fprintf(stderr, "  %-9s MeshLab    %8.3f s\n", c.op.c_str(), row.wall_s);
    rows.push_back(row);
  }
  return rows;
}

//! Blender's Decimate modifier (collapse, ratio 0.1) applied with bpy.ops.object.modifier_apply,
//! timed inside the script around that call alone. The mesh goes in and out as raw arrays.
Row run_blender(const fs::path& dir, const Reference& ref) {
  Row row{kOpDecimate, "Blender", "Decimate modifier (collapse 0.1), bpy.ops.object.modifier_apply only"};
  const hedge::Soup& soup = input().soup;
  {
    std::ofstream p(dir / "in_positions.f32", std::ios::binary);
    p.write(reinterpret_cast<const char*>(soup.positions.data()),
            static_cast<std::streamsize>(soup.positions.size() * sizeof(hedge::Point)));
    std::ofstream s(dir / "in_sizes.i32", std::ios::binary);
    s.write(reinterpret_cast<const char*>(soup.face_sizes.data()),
            static_cast<std::streamsize>(soup.face_sizes.size() * sizeof(std::uint32_t)));
    std::ofstream c(dir / "in_corners.i32", std::ios::binary);
    c.write(reinterpret_cast<const char*>(soup.corners.data()),
            static_cast<std::streamsize>(soup.corners.size() * sizeof(std::uint32_t)));
  }
  const std::string script = R"PY(import sys, time, os
import bpy, numpy as np
d = sys.argv[sys.argv.index("--") + 1]
ratio = float(sys.argv[sys.argv.index("--") + 2])
P = np.fromfile(os.path.join(d, "in_positions.f32"), dtype=np.float32)
S = np.fromfile(os.path.join(d, "in_sizes.i32"), dtype=np.int32)
C = np.fromfile(os.path.join(d, "in_corners.i32"), dtype=np.int32)
me = bpy.data.meshes.new("input")
me.vertices.add(len(P) // 3)
me.vertices.foreach_set("co", P)
me.loops.add(len(C))
me.loops.foreach_set("vertex_index", C)
me.polygons.add(len(S))
starts = np.zeros(len(S), dtype=np.int32)
starts[1:] = np.cumsum(S)[:-1]
me.polygons.foreach_set("loop_start", starts)
me.polygons.foreach_set("loop_total", S)
me.update(calc_edges=True)
ob = bpy.data.objects.new("input", me)
bpy.context.scene.collection.objects.link(ob)
bpy.context.view_layer.objects.active = ob
ob.select_set(True)
mod = ob.modifiers.new("decimate", "DECIMATE")
mod.decimate_type = "COLLAPSE"
mod.ratio = ratio
mod.show_viewport = False  # evaluated once, by the apply (see the hosts notes)
t0 = time.perf_counter()
bpy.ops.object.modifier_apply(modifier="decimate")
t1 = time.perf_counter()
me = ob.data
P = np.empty(len(me.vertices) * 3, dtype=np.float32)
me.vertices.foreach_get("co", P)
S = np.empty(len(me.polygons), dtype=np.int32)
me.polygons.foreach_get("loop_total", S)
C = np.empty(len(me.loops), dtype=np.int32)
me.loops.foreach_get("vertex_index", C)
P.tofile(os.path.join(d, "out_positions.f32"))
S.tofile(os.path.join(d, "out_sizes.i32"))
C.tofile(os.path.join(d, "out_corners.i32"))
with open(os.path.join(d, "blender_time.txt"), "w") as f:
    f.write("%.6f\n" % (t1 - t0))
)PY";
  std::ofstream(dir / "blender_decimate.py") << script;
  std::fprintf(stderr, "  decimate  Blender   ");
  const std::string command = "HOME=" + quote((dir / "home").string()) + " TMPDIR=" + quote(dir.string()) +
                              " blender -b --factory-startup --python-exit-code 1 --python " +
                              quote((dir / "blender_decimate.py").string()) + " -- " + quote(dir.string()) + " " +
                              fmt(kDecimateRatio) + " > " + quote((dir / "blender.log").string()) + " 2>&1";
  fs::create_directories(dir / "home");
  if (std::system(command.c_str()) != 0 || !fs::exists(dir / "blender_time.txt")) {
    row.error = "blender failed (see " + (dir / "blender.log").string() + ")";
    std::fprintf(stderr, " failed\n");
    return row;
  }
  std::ifstream(dir / "blender_time.txt") >> row.wall_s;
  auto read = [&](const char* name, auto& vec) {
    const fs::path path = dir / name;
    vec.resize(fs::file_size(path) / sizeof(vec[0]));
    std::ifstream(path, std::ios::binary)
        .read(reinterpret_cast<char*>(vec.data()), static_cast<std::streamsize>(vec.size() * sizeof(vec[0])));
  };
  hedge::Soup out;
  read("out_positions.f32", out.positions);
  read("out_sizes.i32", out.face_sizes);
  read("out_corners.i32", out.corners);
  try {
    measure(row, out, ref);
  } catch (const std::exception& e) {
    row.error = std::string("cannot use Blender's result: ") + e.what();
  }
  std::fprintf(stderr, " %8.3f s\n", row.wall_s);
  return row;
}

// ---- the table ------------------------------------------------------------------------------

std::string cell(double x, const char* format) {
  if (std::isnan(x)) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, format, x);
  return buf;
}

//! The table's operations, in its order.
constexpr const char* kTableOps[] = {kOpDecimate, kOpRemesh, kOpLoop, kOpCatmull, kOpSqrt3, kOpSmooth};

const char* op_title(const std::string& op) {
  if (op == kOpDecimate) return "decimate to 10%";
  if (op == kOpRemesh) return "remesh, 3 iterations";
  if (op == kOpLoop) return "Loop subdivision x1";
  if (op == kOpCatmull) return "Catmull-Clark x1";
  if (op == kOpSqrt3) return "sqrt3 subdivision x1";
  if (op == kOpSmooth) return "Laplace smooth x10";
  return op.c_str();
}

void print_table(const std::vector<Row>& rows, const std::string& mesh_name, const Reference& ref, int reps) {
  std::printf(
      "\n== hedge_bench operations: %s (%zu faces), fastest of %d round(s) in this process, the libraries in turn; "
      "hosts: 1 run ==\n",
      mesh_name.c_str(), ref.mesh.n_faces(), reps);
  std::printf(
      "ratio = peer wall time / hedge wall time (>1: hedge faster); Hausdorff: symmetric, sampled, as a "
      "fraction of the input's bounding-box diagonal (%.4g)\n\n",
      ref.diagonal);
  std::printf("| operation | mesh | library | wall s | CPU s | peer/hedge | faces out | Hausdorff / diag |\n");
  std::printf("|---|---|---|---:|---:|---:|---:|---:|\n");
  std::map<std::string, double> hedge_wall;
  for (const Row& r : rows)
    if (r.library == "hedge" && r.error.empty()) hedge_wall[r.op] = r.wall_s;
  for (const Row& r : rows) {
    if (!r.error.empty()) {
      std::printf("| %s | %s | %s | failed: %s |||||\n", op_title(r.op), mesh_name.c_str(), r.library.c_str(),
                  r.error.c_str());
      continue;
    }
    const bool peer = r.library != "hedge" && r.library != "hedge+io";
    const double h = hedge_wall.count(r.op) ? hedge_wall[r.op] : NAN;
    std::printf("| %s | %s | %s | %s | %s | %s | %zu | %s |\n", op_title(r.op), mesh_name.c_str(), r.library.c_str(),
                cell(r.wall_s, "%.3f").c_str(), cell(r.cpu_s, "%.3f").c_str(),
                peer ? cell(r.wall_s / h, "%.2fx").c_str() : "", r.faces, cell(r.hausdorff, "%.5f").c_str());
  }
  std::printf("\nremeshing quality (target edge length %.5g = the input's mean edge length)\n", ref.target_length);
  std::printf(
      "| library | edges in [0.8, 1.33] L | min angle | mean min angle | irregular valence | Hausdorff / diag |\n");
  std::printf("|---|---:|---:|---:|---:|---:|\n");
  std::printf("| input | - | %.3g | %.2f | %.1f%% | - |\n", ref.stats.min_angle_degrees,
              ref.stats.mean_min_angle_degrees, 100 * ref.stats.valence_irregular_fraction);
  for (const Row& r : rows) {
    if (r.op != kOpRemesh || !r.has_stats || r.library == "hedge+io") continue;
    std::printf("| %s | %.1f%% | %.3g | %.2f | %.1f%% | %.5f |\n", r.library.c_str(), 100 * r.in_band,
                r.stats.min_angle_degrees, r.stats.mean_min_angle_degrees, 100 * r.stats.valence_irregular_fraction,
                r.hausdorff);
  }
  std::printf("\nwhat each time includes\n");
  std::map<std::string, bool> seen;
  for (const Row& r : rows) {
    const std::string key = r.op + "/" + r.library;
    if (seen[key]) continue;
    seen[key] = true;
    std::printf("  %-9s %-9s %s\n", r.op.c_str(), r.library.c_str(), r.scope.c_str());
  }
  std::printf(
      "Building each library's mesh from the soup and converting its result back are outside the times "
      "(except hedge+io). hedge's subdivision and smoothing use two threads (see CPU s); the peers' run on one.\n");
}

}  // namespace

int run_operation_table(int reps, bool hosts, const std::vector<std::string>& only) {
  const hedge::Soup& soup = input().soup;
  const std::string mesh_name = fs::path(input().path).filename().string();
  Reference ref;
  ref.mesh = hedge::build(soup).mesh;
  ref.stats = hedge::mesh_statistics(ref.mesh);
  ref.diagonal = ref.stats.bbox_diagonal;
  ref.target_length = ref.stats.edge_length_mean;

  std::vector<Row> rows;
  const std::vector<std::pair<std::string, std::vector<OpEntry>>> libraries = {
      {"hedge", hedge_operations()},
      {"OpenMesh", openmesh_operations()},
      {"CGAL", cgal_operations()},
      {"meshopt_simplify", meshopt_simplify_operations()},
      {"meshopt_simplifySloppy", meshopt_sloppy_operations()}};
  std::fprintf(stderr, "operations on %s, %d round(s), every library once a round:\n", mesh_name.c_str(), reps);
  for (const char* op : kTableOps) {
    if (!only.empty() && std::find(only.begin(), only.end(), op) == only.end()) continue;
    std::vector<Contender> contenders;
    for (const auto& [library, entries] : libraries) {
      bool first_hedge = true;
      for (const OpEntry& e : entries) {
        if (e.op != op) continue;
        std::string name = library;
        if (library == "hedge") {
          name = first_hedge ? "hedge" : "hedge+io";
          first_hedge = false;
        }
        contenders.push_back({&e, Row{e.op, name, e.scope}, {}});
      }
    }
    run_rounds(contenders, reps, ref);
    for (Contender& c : contenders) {
      if (c.row.error.empty()) measure(c.row, c.last.output, ref);
      rows.push_back(std::move(c.row));
    }
  }

  if (hosts) {
    char pattern[] = "/tmp/hedge_bench_hosts.XXXXXX";
    if (!mkdtemp(pattern)) {
      std::fprintf(stderr, "hedge_bench: cannot make a temporary folder\n");
      return 1;
    }
    const fs::path dir = pattern;
    const fs::path input_ply = dir / "input.ply";
    hedge::write_mesh(soup, input_ply.string());
    std::vector<Row> meshlab = run_meshlab(dir, input_ply, ref, soup.n_faces());
    Row blender = run_blender(dir, ref);
    // Each host's rows next to the library rows of the same operation.
    std::vector<Row> merged;
    for (const char* op : kTableOps) {
      for (const Row& r : rows)
        if (r.op == op) merged.push_back(r);
      for (const Row& r : meshlab)
        if (r.op == op) merged.push_back(r);
      if (blender.op == op) merged.push_back(blender);
    }
    rows = std::move(merged);
    std::fprintf(stderr, "host files kept in %s\n", dir.c_str());
  }
  print_table(rows, mesh_name, ref, reps);
  return 0;
}

}  // namespace bench
