// What a MeshLab filter plugin makes of the catalogue, whatever the plugin API version
// (2020.09 MeshFilterInterface, 2022+ FilterPlugin): names, help, parameter kinds and the run.
#pragma once

#include <QString>
#include <QStringList>
#include <QVariant>
#include <map>
#include <string>

#include "hedge/catalogue.h"
#include "meshlab_api.h"

namespace hedge::meshlab {

//! The operation behind a filter id (the catalogue index, which both glue versions use as id).
const Operation& operation_at(int id);
//! "Hedge: Decimate": the menu entry and the name .mlx scripts use.
QString filter_name(const Operation& op);
//! "hedge_decimate": the name pymeshlab gives the filter (2022+: `ms.hedge_decimate(...)`).
QString python_filter_name(const Operation& op);
//! The catalogue's help as MeshLab's rich text.
QString filter_info(const Operation& op);
//! MeshLab's FilterClass value for the catalogue category (the values are the same in 2020.09
//! and 2022+): Remeshing, Smoothing, Cleaning, Measure; anything else Generic.
int filter_class(const Operation& op);

//! What a filter needs of the mesh before it runs (faces), as MeshModel bits.
int precondition_mask(const Operation& op);
//! What a filter changes (the whole mesh is rebuilt, or nothing), as MeshModel bits.
int postcondition_mask(const Operation& op);

//! Which Rich parameter class holds a parameter.
enum class RichKind { boolean, integer, real, bounded_real, choice, text };
//! Reals with both ends get a slider (RichDynamicFloat); reals with no upper limit are plain
//! RichFloat fields.
RichKind rich_kind(const ParamSpec& spec);
//! "RichBool", "RichInt", "RichFloat", "RichDynamicFloat", "RichEnum", as .mlx scripts spell them.
const char* rich_type_name(RichKind kind);
//! The help, then what is allowed, the default and the name to use in scripts.
QString param_tooltip(const ParamSpec& spec);
//! An integer range clamped to what MeshLab's int parameters hold.
int int_bound(double bound);

//! Adds one Rich parameter per catalogue parameter of `op` to `parameters`, with its default,
//! label and tooltip: what initParameterSet (2020.09) and initParameterList (2022+) give MeshLab.
void add_parameters(const Operation& op, RichParameterList& parameters);
//! The values MeshLab hands a filter as hedge values, for resolve_params; parameters missing
//! from `parameters` are left out (they take their defaults there), and a value of a type hedge
//! never declares is passed as its type name, to be refused with a message.
std::map<std::string, Value> given_values(const Operation& op, const RichParameterList& parameters);

//! A MeshLab float (single precision) as the decimal a person typed: 0.1f -> 0.1, not
//! 0.100000001, so that a range's ends stay allowed.
double real_from_float(float value);

//! What a run gives MeshLab back.
struct ModelRun {
  QStringList lines;                       //!< to log: the report, what building repaired, timings
  std::map<std::string, QVariant> report;  //!< the report's entries (and "messages"), for 2022+'s applyFilter
};

//! Runs `op` on the mesh of `model`: checks the parameters (resolve_params), reads the mesh,
//! runs the operation with progress through `cb`, and writes the result back. Throws Error, and
//! then `model` is untouched: nothing is written before the result is complete.
ModelRun run_on_model(const Operation& op, const std::map<std::string, Value>& given, MeshModel& model,
                      vcg::CallBackPos* cb);

}  // namespace hedge::meshlab
