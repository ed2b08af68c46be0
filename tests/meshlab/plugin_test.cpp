// The plugin inside MeshLab's own library, in process: libfilter_hedge.so and MeshLab's io_base
// plugin loaded into a real MeshDocument, to check what a batch run cannot show: a failed or
// cancelled filter leaves the mesh exactly as it was, progress stages arrive, deleted elements
// are skipped, selection and custom attributes survive, polygons come back as faux-edge fans.
// Built for every MeshLab version: 2020.09 (MeshFilterInterface, plugins loaded with
// QPluginLoader) and 2021.05+ (FilterPlugin, loaded by MeshLab's own plugin manager, with its
// checks; run inside the version's root). The few API differences are in the block below.
// MeshLab's headers first: vcg's own headers need what they include before them.
#include "meshlab_api.h"
#if HEDGE_MESHLAB_FILTER_PLUGIN
#include <common/globals.h>
#include <common/mlexception.h>
#include <common/plugins/interfaces/filter_plugin.h>
#include <common/plugins/plugin_manager.h>
#include <common/utilities/load_save.h>
#else
#include <common/interfaces.h>
#endif

#include <gtest/gtest.h>
#include <vcg/complex/allocate.h>

#include <QApplication>
#include <QPluginLoader>
#include <algorithm>
#include <array>
#include <cstdlib>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "hedge/catalogue.h"

namespace {

#if HEDGE_MESHLAB_FILTER_PLUGIN
FilterPlugin* hedge_plugin = nullptr;
// 2021.05+ hold an enum's index and a slider's value as plain int and float values.
using DynamicFloatValue = FloatValue;
using EnumValue = IntValue;
#else
MeshFilterInterface* hedge_plugin = nullptr;
MeshIOInterface* io_plugin = nullptr;
#endif
// The message of the last failed filter (2020.09: errorMsg(); 2021.05+: the MLException thrown).
std::string last_error;
// What the last filter returned (2021.05+: its report; 2020.09: nothing).
std::map<std::string, QVariant> last_result;

RichParameterList default_parameters(QAction* action, MeshDocument& document) {
  RichParameterList parameters;
#if HEDGE_MESHLAB_FILTER_PLUGIN
  parameters = hedge_plugin->initParameterList(action, document);
#else
  hedge_plugin->initParameterSet(action, document, parameters);
#endif
  return parameters;
}

bool apply_filter(QAction* action, MeshDocument& document, const RichParameterList& parameters, vcg::CallBackPos* cb) {
  last_error.clear();
  last_result.clear();
#if HEDGE_MESHLAB_FILTER_PLUGIN
  try {
    unsigned int post_condition = 0;
    last_result = hedge_plugin->applyFilter(action, parameters, document, post_condition, cb);
    return true;
  } catch (const MLException& e) {
    last_error = e.what();
    return false;
  }
#else
  const bool applied = hedge_plugin->applyFilter(action, document, parameters, cb);
  if (!applied) last_error = hedge_plugin->errorMsg().toStdString();
  return applied;
#endif
}

// Everything a filter could touch, as plain values, so "untouched" is one comparison.
struct Snapshot {
  int vn = 0, fn = 0, mask = 0;
  std::size_t vert_size = 0, face_size = 0;
  std::vector<float> positions, normals, vertex_quality, face_quality, wedge_uv;
  std::vector<int> vertex_color, vertex_flags, faces, face_color, face_flags, wedge_n;
  std::vector<float> bbox;
  bool operator==(const Snapshot&) const = default;
};

Snapshot snapshot(const MeshModel& model) {
  const CMeshO& m = model.cm;
  Snapshot s;
  s.vn = m.vn;
  s.fn = m.fn;
  s.mask = model.dataMask();
  s.vert_size = m.vert.size();
  s.face_size = m.face.size();
  for (const CVertexO& v : m.vert) {
    for (int k = 0; k < 3; ++k) {
      s.positions.push_back(v.cP()[k]);
      s.normals.push_back(v.cN()[k]);
    }
    for (int k = 0; k < 4; ++k) s.vertex_color.push_back(v.cC()[k]);
    s.vertex_quality.push_back(v.cQ());
    s.vertex_flags.push_back(v.cFlags());
  }
  for (const CFaceO& f : m.face) {
    for (int j = 0; j < 3; ++j) {
      s.faces.push_back(f.cV(j) ? static_cast<int>(f.cV(j) - &m.vert.front()) : -1);
      if (m.face.IsWedgeTexCoordEnabled()) {
        s.wedge_uv.push_back(f.cWT(j).U());
        s.wedge_uv.push_back(f.cWT(j).V());
        s.wedge_n.push_back(f.cWT(j).N());
      }
    }
    if (m.face.IsColorEnabled())
      for (int k = 0; k < 4; ++k) s.face_color.push_back(f.cC()[k]);
    if (m.face.IsQualityEnabled()) s.face_quality.push_back(f.cQ());
    s.face_flags.push_back(f.cFlags());
  }
  for (int k = 0; k < 3; ++k) {
    s.bbox.push_back(m.bbox.min[k]);
    s.bbox.push_back(m.bbox.max[k]);
  }
  return s;
}

QAction* action_of(const std::string& op_id) {
  const hedge::Operation& op = hedge::find_operation(op_id);
  for (QAction* action : hedge_plugin->actions())
    if (action->text().toStdString() == "Hedge: " + op.title) return action;
  return nullptr;
}

// A document holding one mesh read by MeshLab's own PLY/OFF reader, prepared as meshlabserver does.
struct Document {
  MeshDocument document;
  MeshModel* model = nullptr;
  GLLogStream log;

  explicit Document(const std::string& path) {
#if HEDGE_MESHLAB_FILTER_PLUGIN
    model = meshlab::loadMeshWithStandardParameters(QString::fromStdString(path), document).front();
#else
    model = document.addNewMesh(QString::fromStdString(path), "mesh", true);
    const QString format = QFileInfo(QString::fromStdString(path)).suffix().toLower();
    RichParameterList pre;
    io_plugin->initPreOpenParameter(format, QString::fromStdString(path), pre);
    int mask = 0;
    if (!io_plugin->open(format, QString::fromStdString(path), *model, mask, pre))
      throw std::runtime_error("MeshLab could not open " + path);
    model->Enable(mask);
    vcg::tri::UpdateNormal<CMeshO>::PerFaceNormalized(model->cm);
    if (!(mask & vcg::tri::io::Mask::IOM_VERTNORMAL)) vcg::tri::UpdateNormal<CMeshO>::PerVertexAngleWeighted(model->cm);
    vcg::tri::UpdateBounding<CMeshO>::Box(model->cm);
#endif
    hedge_plugin->setLog(&log);
  }

  RichParameterList defaults(QAction* action) { return default_parameters(action, document); }

  bool apply(const std::string& op_id, const RichParameterList& parameters, vcg::CallBackPos* cb = nullptr) {
    return apply_filter(action_of(op_id), document, parameters, cb);
  }
  bool apply(const std::string& op_id) { return apply(op_id, defaults(action_of(op_id))); }

  ~Document() { hedge_plugin->setLog(nullptr); }

  std::string log_text() const {
    QStringList lines;
    log.print(lines);
    return lines.join("\n").toStdString();
  }
};

std::string mesh_path(const char* name) { return std::string(HEDGE_MESH_DIR) + "/" + name; }

// MeshLab's callback is a plain function: the recording and cancelling state lives here.
std::vector<std::pair<int, std::string>> progress_calls;
int cancel_at_call = -1;
bool record_progress(const int percent, const char* text) {
  progress_calls.emplace_back(percent, text);
  return cancel_at_call < 0 || static_cast<int>(progress_calls.size()) < cancel_at_call;
}

class PluginTest : public ::testing::Test {
 protected:
  void SetUp() override {
    progress_calls.clear();
    cancel_at_call = -1;
  }
};

TEST_F(PluginTest, OneFilterPerOperationWithCatalogueParameters) {
  ASSERT_EQ(static_cast<std::size_t>(hedge_plugin->actions().size()), hedge::catalogue().size());
  Document doc(mesh_path("bunny.off"));
  for (const hedge::Operation& op : hedge::catalogue()) {
    QAction* action = action_of(op.id);
    ASSERT_NE(action, nullptr) << op.id;
    RichParameterList parameters = doc.defaults(action);
    EXPECT_EQ(static_cast<std::size_t>(parameters.size()), op.params.size()) << op.id;
    for (const hedge::ParamSpec& p : op.params)
      EXPECT_TRUE(parameters.hasParameter(QString::fromStdString(p.id))) << p.id;
    EXPECT_FALSE(hedge_plugin->filterInfo(action).isEmpty());
  }
}

TEST_F(PluginTest, OutOfRangeParameterIsRefusedAndTheMeshIsUntouched) {
  Document doc(mesh_path("bunny.off"));
  const Snapshot before = snapshot(*doc.model);
  RichParameterList parameters = doc.defaults(action_of("decimate"));
  parameters.setValue("target_ratio", DynamicFloatValue(1.5f));
  EXPECT_FALSE(doc.apply("decimate", parameters));
  const std::string expected = "decimate: parameter target_ratio must be a number from 0 to 1, got '1.5'";
  EXPECT_EQ(last_error, expected);
  EXPECT_NE(doc.log_text().find("Hedge: Decimate failed: " + expected), std::string::npos) << doc.log_text();
  EXPECT_TRUE(snapshot(*doc.model) == before);
}

TEST_F(PluginTest, CancelledMidwayLeavesTheMeshUntouched) {
  std::vector<std::string> cancelled;
  for (const hedge::Operation& op : hedge::catalogue()) {
    if (!op.changes_mesh) continue;
    Document doc(mesh_path("dragon_res3.ply"));
    doc.model->updateDataMask(MeshModel::MM_FACECOLOR | MeshModel::MM_VERTQUALITY);
    const Snapshot before = snapshot(*doc.model);
    progress_calls.clear();
    cancel_at_call = 3;  // after building, inside the operation
    const bool applied = doc.apply(op.id, doc.defaults(action_of(op.id)), record_progress);
    if (progress_calls.size() < 3) {
      // An operation with fewer progress steps cannot be stopped midway; it must then have run.
      EXPECT_TRUE(applied) << op.id;
      continue;
    }
    EXPECT_FALSE(applied) << op.id;
    EXPECT_EQ(last_error, "cancelled by the user") << op.id;
    EXPECT_TRUE(snapshot(*doc.model) == before) << op.id << " changed the mesh although it was cancelled";
    cancelled.push_back(op.id);
  }
  std::string names;
  for (const std::string& id : cancelled) names += id + " ";
  std::printf("cancelled midway: %s\n", names.c_str());
  EXPECT_NE(std::find(cancelled.begin(), cancelled.end(), "decimate"), cancelled.end());
}

TEST_F(PluginTest, ProgressReportsTheOperationsStages) {
  Document doc(mesh_path("dragon_res3.ply"));
  ASSERT_TRUE(doc.apply("decimate", doc.defaults(action_of("decimate")), record_progress)) << doc.log_text();
  ASSERT_GE(progress_calls.size(), 3u);
  EXPECT_EQ(progress_calls.front().second, "Hedge: Decimate: building the half-edge mesh");
  std::set<std::string> stages;
  for (const auto& [percent, text] : progress_calls) {
    EXPECT_GE(percent, 0);
    EXPECT_LE(percent, 100);
    EXPECT_EQ(text.rfind("Hedge: Decimate: ", 0), 0u) << text;
    stages.insert(text);
  }
  EXPECT_GE(stages.size(), 3u) << "building, the operation's own stages, writing";
  EXPECT_EQ(progress_calls.back().second, "Hedge: Decimate: writing the result");
}

TEST_F(PluginTest, NoOpKeepsEverythingIncludingSelection) {
  Document doc(mesh_path("bunny.off"));
  doc.model->updateDataMask(MeshModel::MM_VERTCOLOR | MeshModel::MM_FACECOLOR | MeshModel::MM_FACEQUALITY |
                            MeshModel::MM_VERTQUALITY | MeshModel::MM_WEDGTEXCOORD);
  CMeshO& m = doc.model->cm;
  for (std::size_t i = 0; i < m.vert.size(); ++i) {
    m.vert[i].C() = vcg::Color4b(i % 256, (i * 7) % 256, (i * 13) % 256, 255);
    m.vert[i].Q() = 0.25f * static_cast<float>(i);
    if (i % 5 == 0) m.vert[i].SetS();
  }
  for (std::size_t i = 0; i < m.face.size(); ++i) {
    m.face[i].C() = vcg::Color4b((i * 3) % 256, 10, 20, 200);
    m.face[i].Q() = -static_cast<float>(i);
    for (int j = 0; j < 3; ++j) {
      m.face[i].WT(j) = vcg::TexCoord2f(0.001f * static_cast<float>(i), 0.5f + 0.1f * static_cast<float>(j));
      m.face[i].WT(j).N() = static_cast<short>(i % 3);
    }
    if (i % 7 == 0) m.face[i].SetS();
  }
  const Snapshot before = snapshot(*doc.model);
  ASSERT_TRUE(doc.apply("repair")) << doc.log_text();
  const Snapshot after = snapshot(*doc.model);
  EXPECT_EQ(after.positions, before.positions);
  EXPECT_EQ(after.normals, before.normals);
  EXPECT_EQ(after.vertex_color, before.vertex_color);
  EXPECT_EQ(after.vertex_quality, before.vertex_quality);
  EXPECT_EQ(after.faces, before.faces);
  EXPECT_EQ(after.face_color, before.face_color);
  EXPECT_EQ(after.face_quality, before.face_quality);
  EXPECT_EQ(after.wedge_uv, before.wedge_uv);
  EXPECT_EQ(after.wedge_n, before.wedge_n);
  EXPECT_EQ(after.vertex_flags, before.vertex_flags) << "selection";
  EXPECT_EQ(after.face_flags, before.face_flags) << "selection";
  EXPECT_TRUE(after == before);
}

// The faces with selection `want`, each as its three corner positions from the smallest on, sorted.
std::vector<std::vector<float>> faces_selected(const CMeshO& m, bool want) {
  std::vector<std::vector<float>> out;
  for (const CFaceO& f : m.face) {
    if (f.IsD() || f.IsS() != want) continue;
    std::vector<std::vector<float>> corners;
    for (int j = 0; j < 3; ++j) corners.push_back({f.cP(j)[0], f.cP(j)[1], f.cP(j)[2]});
    std::rotate(corners.begin(), std::min_element(corners.begin(), corners.end()), corners.end());
    std::vector<float> flat;
    for (const auto& c : corners) flat.insert(flat.end(), c.begin(), c.end());
    out.push_back(flat);
  }
  std::sort(out.begin(), out.end());
  return out;
}

// MeshLab's face selection drives selection_only: faces outside it come back as they were.
TEST_F(PluginTest, SelectionOnlyKeepsTheFacesOutsideTheSelection) {
  for (const char* op_id : {"decimate", "remesh", "smooth", "make_delaunay", "subdivide"}) {
    SCOPED_TRACE(op_id);
    Document doc(mesh_path("bunny.off"));
    CMeshO& m = doc.model->cm;
    std::vector<float> xs;
    for (const CFaceO& f : m.face) xs.push_back(f.cP(0)[0]);
    std::nth_element(xs.begin(), xs.begin() + std::ptrdiff_t(xs.size() / 2), xs.end());
    const float median = xs[xs.size() / 2];
    for (CFaceO& f : m.face)
      if (f.cP(0)[0] < median) f.SetS();
    const auto outside = faces_selected(m, false), inside = faces_selected(m, true);
    RichParameterList parameters = doc.defaults(action_of(op_id));
    parameters.setValue("selection_only", BoolValue(true));
    ASSERT_TRUE(doc.apply(op_id, parameters)) << doc.log_text();
    EXPECT_EQ(faces_selected(m, false), outside);
    EXPECT_NE(faces_selected(m, true), inside);
    if (std::string(op_id) == "decimate") {
      EXPECT_LT(m.fn, static_cast<int>(outside.size() + inside.size()));
    }
  }
}

// Decimate's weights and locks name vertex attributes: MeshLab's vertex quality, and any
// per-vertex attribute a filter or script added.
TEST_F(PluginTest, DecimateWeighsByQualityAndKeepsLockedVertices) {
  auto faces_right_of = [](const CMeshO& m, float median) {
    int n = 0;
    for (const CFaceO& f : m.face) n += !f.IsD() && f.cP(0)[0] + f.cP(1)[0] + f.cP(2)[0] > 3 * median;
    return n;
  };
  Document plain(mesh_path("bunny.off")), weighted(mesh_path("bunny.off"));
  CMeshO& m = weighted.model->cm;
  std::vector<float> xs;
  for (const CVertexO& v : m.vert) xs.push_back(v.cP()[0]);
  std::nth_element(xs.begin(), xs.begin() + std::ptrdiff_t(xs.size() / 2), xs.end());
  const float median = xs[xs.size() / 2];
  weighted.model->updateDataMask(MeshModel::MM_VERTQUALITY);
  auto pin = vcg::tri::Allocator<CMeshO>::AddPerVertexAttribute<float>(m, "pin");
  std::vector<std::array<float, 3>> pinned;
  for (std::size_t i = 0; i < m.vert.size(); ++i) {
    m.vert[i].Q() = m.vert[i].cP()[0] > median ? 1.0f : 0.0f;
    pin[i] = i % 50 == 0 ? 1.0f : 0.0f;
    if (pin[i] != 0) pinned.push_back({m.vert[i].cP()[0], m.vert[i].cP()[1], m.vert[i].cP()[2]});
  }
  RichParameterList parameters = weighted.defaults(action_of("decimate"));
  parameters.setValue("target_ratio", DynamicFloatValue(0.1f));
  RichParameterList plain_parameters = parameters;
  parameters.setValue("weight_attribute", StringValue("quality"));
  parameters.setValue("lock_attribute", StringValue("pin"));
  ASSERT_TRUE(plain.apply("decimate", plain_parameters)) << plain.log_text();
  ASSERT_TRUE(weighted.apply("decimate", parameters)) << weighted.log_text();
  EXPECT_GT(faces_right_of(m, median), faces_right_of(plain.model->cm, median) * 5 / 4);
  std::set<std::array<float, 3>> after;
  for (const CVertexO& v : m.vert)
    if (!v.IsD()) after.insert({v.cP()[0], v.cP()[1], v.cP()[2]});
  for (const auto& p : pinned) EXPECT_TRUE(after.count(p)) << "a locked vertex moved or went";
  // A name the mesh lacks is refused, and the mesh is untouched.
  const int faces = m.fn;
  parameters.setValue("weight_attribute", StringValue("no_such_attribute"));
  EXPECT_FALSE(weighted.apply("decimate", parameters));
  EXPECT_NE(weighted.log_text().find("no vertex attribute 'no_such_attribute'"), std::string::npos)
      << weighted.log_text();
  EXPECT_EQ(m.fn, faces);
}

TEST_F(PluginTest, DeletedElementsAreSkippedAndTheResultIsCompact) {
  Document doc(mesh_path("bunny.off"));
  CMeshO& m = doc.model->cm;
  const int faces = m.fn;
  for (std::size_t i = 0; i < 10; ++i) vcg::tri::Allocator<CMeshO>::DeleteFace(m, m.face[100 * i]);
  ASSERT_EQ(m.fn, faces - 10);
  ASSERT_TRUE(doc.apply("report"));
  EXPECT_NE(doc.log_text().find("Hedge: Mesh Report: faces = " + std::to_string(faces - 10)), std::string::npos);
  ASSERT_TRUE(doc.apply("repair")) << doc.log_text();
  EXPECT_EQ(m.fn, faces - 10);
  EXPECT_EQ(m.face.size(), static_cast<std::size_t>(m.fn)) << "compacted";
  EXPECT_EQ(m.vert.size(), static_cast<std::size_t>(m.vn));
  for (const CFaceO& f : m.face) EXPECT_FALSE(f.IsD());
}

// A face on a deleted vertex is a broken mesh (MeshLab's readers also leave faces pointing past
// the vertex array on indices out of range): refused naming the face, never silently dropped.
TEST_F(PluginTest, FaceOnADeletedVertexIsRefused) {
  Document doc(mesh_path("bunny.off"));
  CMeshO& m = doc.model->cm;
  CVertexO* v = m.face[7].V(2);
  vcg::tri::Allocator<CMeshO>::DeleteVertex(m, *v);
  const Snapshot before = snapshot(*doc.model);
  EXPECT_FALSE(doc.apply("smooth"));
  // The first face on that vertex is named (face 7 or one before it around the vertex).
  const std::string expected = " uses vertex " + std::to_string(v - m.vert.data()) + ", which is deleted";
  const std::string message = last_error;
  EXPECT_EQ(message.rfind("face ", 0), 0u) << message;
  EXPECT_NE(message.find(expected), std::string::npos) << message;
  EXPECT_NE(doc.log_text().find("Hedge: Smooth failed: " + message), std::string::npos) << doc.log_text();
  EXPECT_TRUE(snapshot(*doc.model) == before);
}

TEST_F(PluginTest, CustomAttributesAreCarried) {
  Document doc(mesh_path("bunny.off"));
  CMeshO& m = doc.model->cm;
  auto heat = vcg::tri::Allocator<CMeshO>::AddPerVertexAttribute<float>(m, "heat");
  auto label = vcg::tri::Allocator<CMeshO>::AddPerFaceAttribute<int>(m, "label");
  for (std::size_t i = 0; i < m.vert.size(); ++i) heat[i] = 1.0f + static_cast<float>(i % 10);
  for (std::size_t i = 0; i < m.face.size(); ++i) label[i] = static_cast<int>(i % 4);
  ASSERT_TRUE(doc.apply("subdivide")) << doc.log_text();
  ASSERT_EQ(m.fn, 4 * 3674);
  auto heat_after = vcg::tri::Allocator<CMeshO>::FindPerVertexAttribute<float>(m, "heat");
  auto label_after = vcg::tri::Allocator<CMeshO>::FindPerFaceAttribute<int>(m, "label");
  ASSERT_TRUE(vcg::tri::Allocator<CMeshO>::IsValidHandle(m, heat_after));
  ASSERT_TRUE(vcg::tri::Allocator<CMeshO>::IsValidHandle(m, label_after));
  for (std::size_t i = 0; i < m.vert.size(); ++i) {
    EXPECT_GE(heat_after[i], 1.0f);  // interpolated between the original values
    EXPECT_LE(heat_after[i], 10.0f);
  }
  std::map<int, int> labels;
  for (std::size_t i = 0; i < m.face.size(); ++i) ++labels[label_after[i]];
  EXPECT_EQ(labels.size(), 4u) << "face attributes copied to the child faces";
}

TEST_F(PluginTest, PolygonsComeBackAsFauxEdgeFans) {
  Document doc(mesh_path("bunny.off"));
  RichParameterList parameters = doc.defaults(action_of("subdivide"));
  parameters.setValue("scheme", EnumValue(1));  // catmull_clark
  ASSERT_TRUE(doc.apply("subdivide", parameters)) << doc.log_text();
  CMeshO& m = doc.model->cm;
  EXPECT_EQ(m.fn, 6 * 3674);
  EXPECT_TRUE(doc.model->hasDataMask(MeshModel::MM_POLYGONAL));
  for (const CFaceO& f : m.face)
    EXPECT_EQ(int(f.IsF(0)) + int(f.IsF(1)) + int(f.IsF(2)), 1) << "one diagonal per quad half";
}

TEST_F(PluginTest, PolygonsSurviveAChainOfFilters) {
  Document doc(mesh_path("bunny.off"));
  RichParameterList parameters = doc.defaults(action_of("subdivide"));
  parameters.setValue("scheme", EnumValue(1));  // catmull_clark: 3 quads per triangle, then 4 per quad
  ASSERT_TRUE(doc.apply("subdivide", parameters)) << doc.log_text();
  ASSERT_TRUE(doc.apply("subdivide", parameters)) << doc.log_text();
  EXPECT_EQ(doc.model->cm.fn, 2 * 4 * 3 * 3674) << "the second step saw quads, not triangle pairs";
  ASSERT_TRUE(doc.apply("report"));
  EXPECT_NE(doc.log_text().find("Hedge: Mesh Report: quads = " + std::to_string(4 * 3 * 3674)), std::string::npos);
}

// crease_angle reaches the core through MeshLab's dialog: two sqrt3 steps at 30 degrees keep the
// bunny's creases, each cut in three by the second step with two new triangles on either side.
TEST_F(PluginTest, Sqrt3CreasesFromTheDialog) {
  Document doc(mesh_path("bunny.off"));
  RichParameterList parameters = doc.defaults(action_of("subdivide"));
  parameters.setValue("scheme", EnumValue(2));  // sqrt3
  parameters.setValue("iterations", IntValue(2));
  parameters.setValue("crease_angle", DynamicFloatValue(30));
  ASSERT_TRUE(doc.apply("subdivide", parameters)) << doc.log_text();
  const std::string log = doc.log_text();
  const std::string key = "Hedge: Subdivide: crease_edges = ";
  const std::size_t at = log.find(key);
  ASSERT_NE(at, std::string::npos) << log;
  const int creases = std::stoi(log.substr(at + key.size()));
  EXPECT_GT(creases, 100);
  EXPECT_EQ(doc.model->cm.fn, 9 * 3674 + 4 * creases);
}

TEST_F(PluginTest, NoMeshIsAnErrorNotACrash) {
  MeshDocument empty;
  GLLogStream log;
  hedge_plugin->setLog(&log);
  RichParameterList parameters;  // the report has no parameters
  EXPECT_FALSE(apply_filter(action_of("report"), empty, parameters, nullptr));
  EXPECT_NE(last_error.find("no mesh"), std::string::npos);
}

#if HEDGE_MESHLAB_FILTER_PLUGIN
// What pymeshlab hands back to Python: the report, entry for entry as the log has it.
TEST_F(PluginTest, ApplyFilterReturnsTheReport) {
  Document doc(mesh_path("bunny.off"));
  ASSERT_TRUE(doc.apply("report")) << last_error;
  ASSERT_EQ(last_result.count("faces"), 1u);
  EXPECT_EQ(last_result["faces"].toLongLong(), 3674);
  EXPECT_EQ(last_result["genus"].toLongLong(), 0);
  EXPECT_GT(last_result["area"].toDouble(), 0.0);
  RichParameterList parameters = doc.defaults(action_of("decimate"));
  parameters.setValue("target_faces", IntValue(1000));
  ASSERT_TRUE(doc.apply("decimate", parameters)) << last_error;
  EXPECT_EQ(last_result["faces_after"].toLongLong(), doc.model->cm.fn);
  EXPECT_EQ(last_result["stopped_by"].toString().toStdString(), "target reached");
}

// MeshLab's own loader took the plugin (its version, class, pre/postcondition and arity checks).
TEST_F(PluginTest, PythonNamesAndClasses) {
  for (const hedge::Operation& op : hedge::catalogue()) {
    QAction* action = action_of(op.id);
    ASSERT_NE(action, nullptr) << op.id;
    EXPECT_EQ(hedge_plugin->pythonFilterName(action).toStdString(), "hedge_" + op.id);
    EXPECT_NE(hedge_plugin->getClass(action), FilterPlugin::Generic) << op.id;
    EXPECT_EQ(hedge_plugin->filterArity(action), FilterPlugin::SINGLE_MESH) << op.id;
  }
}
#endif

}  // namespace

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  setenv("QT_QPA_PLATFORM", "offscreen", 1);
  QApplication app(argc, argv);
#if HEDGE_MESHLAB_FILTER_PLUGIN
  try {
    meshlab::pluginManagerInstance().loadPlugin(MESHLAB_IO_PLUGIN_PATH);
    hedge_plugin = dynamic_cast<FilterPlugin*>(meshlab::pluginManagerInstance().loadPlugin(HEDGE_PLUGIN_PATH));
  } catch (const MLException& e) {
    std::fprintf(stderr, "MeshLab refuses a plugin: %s\n", e.what());
    return 1;
  }
  if (!hedge_plugin) {
    std::fprintf(stderr, "%s is not a filter plugin\n", HEDGE_PLUGIN_PATH);
    return 1;
  }
#else
  QPluginLoader hedge_loader(HEDGE_PLUGIN_PATH);
  hedge_plugin = qobject_cast<MeshFilterInterface*>(hedge_loader.instance());
  if (!hedge_plugin) {
    std::fprintf(stderr, "cannot load %s: %s\n", HEDGE_PLUGIN_PATH, qUtf8Printable(hedge_loader.errorString()));
    return 1;
  }
  QPluginLoader io_loader(MESHLAB_IO_PLUGIN_PATH);
  io_plugin = qobject_cast<MeshIOInterface*>(io_loader.instance());
  if (!io_plugin) {
    std::fprintf(stderr, "cannot load %s: %s\n", MESHLAB_IO_PLUGIN_PATH, qUtf8Printable(io_loader.errorString()));
    return 1;
  }
#endif
  return RUN_ALL_TESTS();
}
