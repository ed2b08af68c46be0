// The MeshLab headers hedge's shared plugin code needs, wherever the version keeps them:
// 2020.09 (MeshFilterInterface) has common/meshmodel.h and common/filter_parameter/; 2021.05 and
// later (FilterPlugin: 2022.02, 2025.07) moved them under common/ml_document/ and
// common/parameters/. HEDGE_MESHLAB_FILTER_PLUGIN says which API the headers are.
#pragma once

#if __has_include(<common/plugins/interfaces/filter_plugin.h>)
#define HEDGE_MESHLAB_FILTER_PLUGIN 1
#include <common/ml_document/mesh_document.h>
#include <common/ml_document/mesh_model.h>
#include <common/parameters/rich_parameter_list.h>
#else
#define HEDGE_MESHLAB_FILTER_PLUGIN 0
#include <common/filter_parameter/rich_parameter_list.h>
#include <common/meshmodel.h>
#endif
