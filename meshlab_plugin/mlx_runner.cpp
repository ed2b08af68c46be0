// hedge-mlx: a headless batch runner for MeshLab 2021.05+ (which ship no meshlabserver), built on
// MeshLab's own library: its plugin manager, mesh document, .mlx reader and standard load/save.
//
//   hedge-mlx [OPTIONS] IN OUT SCRIPT.mlx   load IN, run every filter of SCRIPT, save OUT ("-": no save)
//   hedge-mlx [OPTIONS] --list [MESH]       every filter loaded, with its parameters, as JSON
//
// Options:
//   --plugins DIR         load plugins from DIR first (repeatable; also HEDGE_MLX_PLUGINS=DIR:DIR)
//   --no-default-plugins  do not load the system folder nor the user's MeshLabExtraPlugins/<version>
//   -m FLAG...            what to save, as meshlabserver's -m: vc vf vq vn vt fc ff fq fn wc wn wt
//                         (default: the format's own defaults)
//   --keep-going          after a failed filter, run the rest and save anyway (the exit code stays 1)
//
// The log goes to stdout as "LOG: <level> <text>"; what a filter returns (2021.05+'s applyFilter
// map, pymeshlab's return value) as "RESULT: <filter name>: <JSON object>".
// Parameters a script leaves out take the filter's defaults (initParameterList, then the script's
// values override). Exit codes: 0 done; 1 a filter failed (its message on stderr and in the log);
// 2 bad usage, an unreadable script, an unknown filter or parameter; 3 the input could not be
// loaded or the output not saved. Only filter and io plugins are loaded: edit, decorate and
// render plugins need MeshLab's GUI library and a window, which a batch run has not.
#include <common/filterscript.h>
#include <common/globals.h>
#include <common/mlexception.h>
#include <common/plugins/plugin_manager.h>
#include <common/utilities/load_save.h>
#include <unistd.h>

#include <QApplication>
#include <QDir>
#include <QFileInfo>
#include <QJsonArray>
#include <QJsonDocument>
#include <QJsonObject>
#include <QStandardPaths>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace {

enum Exit { done = 0, filter_failed = 1, usage_error = 2, io_error = 3 };

struct Failure {
  int code;
  QString message;
};

void say(const QString& text) { std::fprintf(stderr, "hedge-mlx: %s\n", qUtf8Printable(text)); }

#ifndef HEDGE_MESHLAB_SYSTEM_PLUGINS
#define HEDGE_MESHLAB_SYSTEM_PLUGINS "/usr/lib/x86_64-linux-gnu/meshlab/plugins"
#endif

// Where the MeshLab GUI of this version looks for a user's plugins (Help > Plugin Info > Load
// Plugins copies them there): AppDataLocation of "VCG"/"MeshLab_64bit_fp", then
// MeshLabExtraPlugins/<version>.
QString user_plugin_dir() {
  const QString base = QStandardPaths::writableLocation(QStandardPaths::AppDataLocation);
  return base + "/MeshLabExtraPlugins/" + QString::fromStdString(meshlab::meshlabVersion());
}

struct Options {
  QStringList plugin_dirs;
  bool default_plugins = true;
  bool list = false;
  bool keep_going = false;
  bool save_mask_given = false;
  QStringList save_flags;
  QStringList positional;
};

const std::map<QString, std::pair<int, int>>& save_flag_bits() {
  using M = vcg::tri::io::Mask;
  // meshlabserver's -m flags: the io mask bit, and the MeshModel component it needs.
  static const std::map<QString, std::pair<int, int>> bits = {
      {"vc", {M::IOM_VERTCOLOR, MeshModel::MM_VERTCOLOR}},
      {"vf", {M::IOM_VERTFLAGS, MeshModel::MM_VERTFLAG}},
      {"vq", {M::IOM_VERTQUALITY, MeshModel::MM_VERTQUALITY}},
      {"vn", {M::IOM_VERTNORMAL, MeshModel::MM_VERTNORMAL}},
      {"vt", {M::IOM_VERTTEXCOORD, MeshModel::MM_VERTTEXCOORD}},
      {"fc", {M::IOM_FACECOLOR, MeshModel::MM_FACECOLOR}},
      {"ff", {M::IOM_FACEFLAGS, MeshModel::MM_FACEFLAG}},
      {"fq", {M::IOM_FACEQUALITY, MeshModel::MM_FACEQUALITY}},
      {"fn", {M::IOM_FACENORMAL, MeshModel::MM_FACENORMAL}},
      {"wc", {M::IOM_WEDGCOLOR, MeshModel::MM_WEDGCOLOR}},
      {"wn", {M::IOM_WEDGNORMAL, MeshModel::MM_WEDGNORMAL}},
      {"wt", {M::IOM_WEDGTEXCOORD, MeshModel::MM_WEDGTEXCOORD}},
  };
  return bits;
}

Options parse(const QStringList& arguments) {
  Options options;
  for (int i = 1; i < arguments.size(); ++i) {
    const QString& a = arguments[i];
    if (a == "--plugins") {
      if (++i == arguments.size()) throw Failure{usage_error, "--plugins needs a folder"};
      options.plugin_dirs << arguments[i];
    } else if (a == "--no-default-plugins") {
      options.default_plugins = false;
    } else if (a == "--keep-going") {
      options.keep_going = true;
    } else if (a == "--list") {
      options.list = true;
    } else if (a == "-m") {
      options.save_mask_given = true;
      while (i + 1 < arguments.size() && save_flag_bits().count(arguments[i + 1])) options.save_flags << arguments[++i];
    } else if (a == "-h" || a == "--help") {
      throw Failure{usage_error, ""};
    } else if (a.startsWith("-") && a != "-") {
      throw Failure{usage_error, "unknown option " + a};
    } else {
      options.positional << a;
    }
  }
  const int wanted = options.list ? -1 : 3;
  if (wanted > 0 && options.positional.size() != wanted)
    throw Failure{usage_error,
                  "expected IN OUT SCRIPT.mlx, got " + QString::number(options.positional.size()) + " arguments"};
  if (options.list && options.positional.size() > 1) throw Failure{usage_error, "--list takes at most one mesh"};
  return options;
}

// Loads the filter and io plugins of each folder in order; a file name loaded once is not loaded
// again from a later folder (so --plugins shadows an installed copy). Plugins that do not load are
// reported, not fatal: a script that needs one fails on its unknown filter name.
QJsonArray load_plugins(const Options& options) {
  QStringList dirs = options.plugin_dirs;
  for (const QString& dir : qEnvironmentVariable("HEDGE_MLX_PLUGINS").split(':', Qt::SkipEmptyParts)) dirs << dir;
  if (options.default_plugins) dirs << HEDGE_MESHLAB_SYSTEM_PLUGINS << user_plugin_dir();
  PluginManager& manager = meshlab::pluginManagerInstance();
  std::set<QString> names;
  QJsonArray report;
  for (const QString& dir_name : dirs) {
    QDir dir(dir_name);
    if (!dir.exists()) continue;
    for (const QString& file : dir.entryList({"*.so"}, QDir::Files, QDir::Name)) {
      if (!file.startsWith("libfilter_") && !file.startsWith("libio_")) continue;
      QJsonObject entry{{"file", dir.absoluteFilePath(file)}};
      if (!names.insert(file).second) {
        entry["loaded"] = false;
        entry["error"] = "shadowed by a plugin of the same name loaded before";
      } else {
        try {
          MeshLabPlugin* plugin = manager.loadPlugin(dir.absoluteFilePath(file));
          entry["loaded"] = true;
          entry["name"] = plugin->pluginName();
        } catch (const MLException& e) {
          entry["loaded"] = false;
          entry["error"] = QString::fromLocal8Bit(e.what()).trimmed();
          say("plugin not loaded: " + dir.absoluteFilePath(file) + ": " + entry["error"].toString());
        }
      }
      report.append(entry);
    }
  }
  return report;
}

QJsonValue value_json(const Value& value) {
  if (value.isBool()) return value.getBool();
  if (value.isInt()) return value.getInt();
  if (value.isFloat()) return double(value.getFloat());
  if (value.isString()) return value.getString();
  return value.typeName();
}

QJsonObject parameter_json(const RichParameter& p) {
  QJsonObject o{{"name", p.name()},
                {"type", p.stringType()},
                {"description", p.fieldDescription()},
                {"tooltip", p.toolTip()},
                {"value", value_json(p.value())}};
  if (const auto* e = dynamic_cast<const RichEnum*>(&p)) o["choices"] = QJsonArray::fromStringList(e->enumvalues);
  if (const auto* d = dynamic_cast<const RichDynamicFloat*>(&p)) {
    o["min"] = double(d->min);
    o["max"] = double(d->max);
  }
  return o;
}

// `json_fd` is the real stdout: what plugins print goes to stderr meanwhile (some print to stdout).
int list(const Options& options, const QJsonArray& plugins, int json_fd) {
  MeshDocument document;
  if (options.positional.isEmpty())
    document.addNewMesh(QString(), "empty");
  else
    meshlab::loadMeshWithStandardParameters(options.positional[0], document);
  PluginManager& manager = meshlab::pluginManagerInstance();
  QJsonArray filters;
  for (FilterPlugin* plugin : manager.filterPluginIterator()) {
    for (QAction* action : plugin->actions()) {
      // Some filters' defaults need what the mesh lacks (vcg throws "Missing Component"): their
      // parameters are left out, with the reason.
      QJsonArray parameters;
      QString parameters_error;
      try {
        for (const RichParameter& p : plugin->initParameterList(action, document)) parameters.append(parameter_json(p));
      } catch (const std::exception& e) {
        parameters_error = QString::fromLocal8Bit(e.what());
      }
      filters.append(QJsonObject{{"name", plugin->filterName(action)},
                                 {"python_name", plugin->pythonFilterName(action)},
                                 {"plugin", plugin->pluginName()},
                                 {"file", plugin->pluginFileInfo().absoluteFilePath()},
                                 {"class", int(plugin->getClass(action))},
                                 {"arity", int(plugin->filterArity(action))},
                                 {"preconditions", plugin->getPreConditions(action)},
                                 {"postcondition", plugin->postCondition(action)},
                                 {"info", plugin->filterInfo(action)},
                                 {"parameters", parameters},
                                 {"parameters_error", parameters_error}});
    }
  }
  QJsonObject out{{"meshlab_version", QString::fromStdString(meshlab::meshlabVersion())},
                  {"user_plugin_dir", user_plugin_dir()},
                  {"plugins", plugins},
                  {"filters", filters}};
  const QByteArray json = QJsonDocument(out).toJson();
  std::fflush(stdout);
  for (qsizetype written = 0; written < json.size();) {
    const ssize_t n = ::write(json_fd, json.constData() + written, static_cast<std::size_t>(json.size() - written));
    if (n <= 0) throw Failure{io_error, "cannot write the list"};
    written += n;
  }
  return done;
}

// The script's values over the filter's defaults. A parameter the filter does not have, or of
// another type, is refused: MeshLab would otherwise read one type's value as another.
RichParameterList parameters_for(FilterPlugin* plugin, QAction* action, const MeshDocument& document,
                                 const QString& filter, const RichParameterList& given) {
  RichParameterList parameters = plugin->initParameterList(action, document);
  for (const RichParameter& p : given) {
    if (!parameters.hasParameter(p.name())) {
      QStringList known;
      for (const RichParameter& q : parameters) known << q.name();
      throw Failure{usage_error, "filter '" + filter + "' has no parameter '" + p.name() +
                                     "' (its parameters: " + known.join(", ") + ")"};
    }
    const RichParameter& expected = parameters.getParameterByName(p.name());
    if (expected.value().typeName() != p.value().typeName())
      throw Failure{usage_error, "filter '" + filter + "': parameter '" + p.name() + "' holds a " +
                                     expected.value().typeName() + " value, the script gives a " +
                                     p.value().typeName() + " (" + p.stringType() + ")"};
    parameters.setValue(p.name(), p.value());
  }
  return parameters;
}

bool no_progress(const int, const char*) { return true; }

void run_filter(MeshDocument& document, const QString& filter, const RichParameterList& given) {
  PluginManager& manager = meshlab::pluginManagerInstance();
  QAction* action = manager.filterAction(filter);
  if (action == nullptr) throw Failure{usage_error, "no filter named '" + filter + "' is loaded"};
  FilterPlugin* plugin = manager.getFilterPluginFromAction(action);
  if (plugin->requiresGLContext(action))
    throw Failure{filter_failed, "filter '" + filter + "' needs an OpenGL context, which hedge-mlx does not make"};
  const RichParameterList parameters = parameters_for(plugin, action, document, filter, given);
  if (document.mm() != nullptr) {
    QStringList missing;
    if (!plugin->isFilterApplicable(action, *document.mm(), missing))
      throw Failure{filter_failed, "filter '" + filter + "' cannot run on this mesh: it needs " + missing.join(", ")};
    document.mm()->updateDataMask(plugin->getRequirements(action));
  }
  plugin->setLog(&document.Log);
  unsigned int post_condition = MeshModel::MM_UNKNOWN;
  std::map<std::string, QVariant> result;
  try {
    result = plugin->applyFilter(action, parameters, document, post_condition, no_progress);
  } catch (const std::exception& e) {
    throw Failure{filter_failed, "filter '" + filter + "' failed: " + QString::fromLocal8Bit(e.what())};
  }
  if (!result.empty()) {
    QJsonObject object;
    for (const auto& [key, value] : result) object[QString::fromStdString(key)] = QJsonValue::fromVariant(value);
    std::printf("RESULT: %s: %s\n", qUtf8Printable(filter),
                QJsonDocument(object).toJson(QJsonDocument::Compact).constData());
  }
}

void save(MeshModel& model, const QString& path, const Options& options, GLLogStream& log) {
  if (!options.save_mask_given) {
    meshlab::saveMeshWithStandardParameters(path, model, &log);
    return;
  }
  const QString extension = QFileInfo(path).suffix().toLower();
  IOPlugin* plugin = meshlab::pluginManagerInstance().outputMeshPlugin(extension);
  if (plugin == nullptr) throw MLException("no plugin saves ." + extension + " files");
  int capability = 0, default_bits = 0;
  plugin->exportMaskCapability(extension, capability, default_bits);
  // The flags asked for, of what the format can hold and the mesh has.
  int mask = vcg::tri::io::Mask::IOM_VERTCOORD | vcg::tri::io::Mask::IOM_FACEINDEX;
  for (const QString& flag : options.save_flags) {
    const auto [bit, component] = save_flag_bits().at(flag);
    if (model.hasDataMask(component)) mask |= bit;
  }
  mask |= default_bits & vcg::tri::io::Mask::IOM_BITPOLYGONAL;
  mask &= capability | vcg::tri::io::Mask::IOM_VERTCOORD | vcg::tri::io::Mask::IOM_FACEINDEX;
  if (mask & vcg::tri::io::Mask::IOM_BITPOLYGONAL) model.updateDataMask(MeshModel::MM_FACEFACETOPO);
  plugin->setLog(&log);
  plugin->save(extension, path, model, mask, plugin->initSaveParameter(extension, model), no_progress);
}

int run(const Options& options) {
  const QString in = options.positional[0], out = options.positional[1], script_path = options.positional[2];
  FilterScript script;
  if (!QFileInfo(script_path).isReadable()) throw Failure{usage_error, "cannot read the script " + script_path};
  if (!script.open(script_path))
    throw Failure{usage_error, script_path + " is not a MeshLab filter script (<FilterScript> XML)"};

  MeshDocument document;
  int printed = 0;
  const auto print_log = [&] {
    const auto& entries = document.Log.logStringList();
    for (; printed < entries.size(); ++printed)
      std::printf("LOG: %d %s\n", entries[printed].first, qUtf8Printable(entries[printed].second));
    std::fflush(stdout);
  };
  QObject::connect(&document.Log, &GLLogStream::logUpdated, print_log);

  try {
    meshlab::loadMeshWithStandardParameters(in, document, no_progress);
  } catch (const std::exception& e) {
    throw Failure{io_error, "cannot load " + in + ": " + QString::fromLocal8Bit(e.what()).trimmed()};
  }
  if (document.mm() == nullptr) throw Failure{io_error, "cannot load " + in + ": no mesh in the file"};
  say(QString("loaded %1: %2 vertices, %3 faces").arg(in).arg(document.mm()->cm.vn).arg(document.mm()->cm.fn));

  int code = done;
  for (const FilterNameParameterValuesPair& step : script) {
    say("applying '" + step.filterName() + "'");
    try {
      run_filter(document, step.filterName(), step.second);
    } catch (const Failure& failure) {
      print_log();
      if (failure.code != filter_failed || !options.keep_going) throw;
      say(failure.message + " (--keep-going: the next filters run)");
      code = filter_failed;
    }
    print_log();
  }

  if (out != "-") {
    if (document.mm() == nullptr) throw Failure{io_error, "cannot save " + out + ": the script left no mesh"};
    try {
      save(*document.mm(), out, options, document.Log);
    } catch (const std::exception& e) {
      throw Failure{io_error, "cannot save " + out + ": " + QString::fromLocal8Bit(e.what()).trimmed()};
    }
    // Some writers report a failure only in the log: check the file is there.
    if (!QFileInfo(out).isFile() || QFileInfo(out).size() == 0) throw Failure{io_error, "cannot save " + out};
    say(QString("saved %1: %2 vertices, %3 faces").arg(out).arg(document.mm()->cm.vn).arg(document.mm()->cm.fn));
  }
  print_log();
  return code;
}

}  // namespace

int main(int argc, char* argv[]) {
  // No X server needed: Qt's offscreen platform, unless the caller chose one.
  if (qEnvironmentVariableIsEmpty("QT_QPA_PLATFORM")) qputenv("QT_QPA_PLATFORM", "offscreen");
  // MeshLab's qDebug chatter (and its copy of every log line) stays out; the log is on stdout.
  if (qEnvironmentVariableIsEmpty("QT_LOGGING_RULES")) qputenv("QT_LOGGING_RULES", "*.debug=false");
  QApplication application(argc, argv);
  // The names MeshLab's GUI runs under, so AppDataLocation is its folder (user plugins).
  QApplication::setOrganizationName("VCG");
  QApplication::setApplicationName(QString("MeshLab_64bit_") + (sizeof(Scalarm) == sizeof(double) ? "dp" : "fp"));
  std::setlocale(LC_NUMERIC, "C");
  try {
    const Options options = parse(QApplication::arguments());
    int json_fd = -1;
    if (options.list) {
      std::fflush(stdout);
      json_fd = ::dup(STDOUT_FILENO);
      ::dup2(STDERR_FILENO, STDOUT_FILENO);
    }
    const QJsonArray plugins = load_plugins(options);
    return options.list ? list(options, plugins, json_fd) : run(options);
  } catch (const Failure& failure) {
    if (failure.code == usage_error && failure.message.isEmpty()) {
      std::fputs(
          "usage: hedge-mlx [--plugins DIR]... [--no-default-plugins] [-m FLAG...] IN OUT SCRIPT.mlx\n"
          "       hedge-mlx [--plugins DIR]... [--no-default-plugins] --list [MESH]\n",
          stderr);
    } else {
      say(failure.message);
    }
    return failure.code;
  } catch (const std::exception& e) {
    say(QString("error: ") + QString::fromLocal8Bit(e.what()));
    return io_error;
  }
}
