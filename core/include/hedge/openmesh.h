// OpenMesh interop: OpenMesh::PolyMesh_ArrayKernelT / TriMesh_ArrayKernelT (any traits) to and
// from hedge::Soup, and .om files through OpenMesh's own IO. Header-only; link OpenMeshCore
// (CMake: hedge::openmesh, defined when libopenmesh-dev is found; it defines HEDGE_HAS_OPENMESH).
//
// The contract, both ways:
// - Vertices keep their index order, faces OpenMesh's face index order, and each face its
//   corners in order (OpenMesh face corner k is the target of the k-th half-edge of
//   fh_range(face), starting at halfedge_handle(face)). Positions become float (hedge::Point).
// - Properties travel by name. The standard ones map to the soup's shared names: vertex and
//   face normals to "normal" (f32 x3), colours to "color" (u8 x4 RGBA for integer colours,
//   f32 x4 otherwise; alpha 255 or 1 where OpenMesh has none), vertex texcoords 2D to "uv"
//   (vertex), half-edge texcoords 2D and normals and colours to "uv"/"normal"/"color" (corner).
//   Custom vertex, face and half-edge (as corner) properties of float, double, the integer
//   types, bool (u8) and OpenMesh::VectorT<scalar, 2..4> become channels of the same name,
//   scalar type and component count. Everything else (edge and mesh properties, other types,
//   unnamed properties, the other standard ones) is listed in `skipped`, never dropped
//   silently. Status flags are bookkeeping and not carried.
// - Half-edge values live only on face corners: boundary half-edges get zeros on the way in.
//
// Soup -> OpenMesh never loses a face. OpenMesh's add_face refuses faces that would make an
// edge with three faces or a vertex with two fans ("complex edge", "complex vertex"); so the
// soup goes through hedge::build() first, which splits such places into manifold copies, and
// every face arrives with its corners in order (build() runs with orient = false unless asked,
// so no face is turned over: inconsistent orientation is split too). The copies come after
// the soup's vertices; FromSoupReport says how many there are and which soup vertex each
// copies. Only faces with fewer than three distinct vertices, which no half-edge mesh can hold,
// are left out, and they are listed. A TriMesh splits polygons into triangle fans itself;
// face_source tells which soup face each triangle came from.
#pragma once

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>
#include <algorithm>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "hedge/build.h"
#include "hedge/error.h"
#include "hedge/soup.h"

namespace hedge::openmesh {

//! A property or channel a conversion could not carry, and why.
struct SkippedProperty {
  std::string name;
  std::string where;  //!< "vertex", "halfedge", "edge", "face", "mesh" (OpenMesh) or a soup domain
  std::string reason;
};

struct FromSoupOptions {
  //! Let build() turn faces over to orient each component consistently, instead of splitting
  //! vertices where neighbouring faces disagree. Turned faces have their corners reversed.
  bool orient = false;
};

struct FromSoupReport {
  BuildReport build;                         //!< what build() split, flipped or skipped
  std::size_t vertex_copies = 0;             //!< OpenMesh vertices beyond the soup's own
  std::vector<std::uint32_t> vertex_source;  //!< OpenMesh vertex -> soup vertex
  std::vector<std::uint32_t> face_source;    //!< OpenMesh face -> soup face
  std::vector<std::uint32_t> skipped_faces;  //!< soup faces of fewer than 3 distinct vertices
  std::vector<SkippedProperty> skipped;      //!< channels not carried
};

namespace detail {

inline constexpr int kNone = -1;

// The C++ scalar types a property may hold, mapped to the channel scalar of their size.
template <class S>
constexpr std::optional<ScalarType> scalar_type_of() {
  if constexpr (std::is_same_v<S, bool>) return ScalarType::u8;
  if constexpr (std::is_floating_point_v<S>) {
    if constexpr (sizeof(S) == 4) return ScalarType::f32;
    if constexpr (sizeof(S) == 8) return ScalarType::f64;
  } else if constexpr (std::is_integral_v<S>) {
    constexpr bool is_signed = std::is_signed_v<S>;
    if constexpr (sizeof(S) == 1) return is_signed ? ScalarType::i8 : ScalarType::u8;
    if constexpr (sizeof(S) == 2) return is_signed ? ScalarType::i16 : ScalarType::u16;
    if constexpr (sizeof(S) == 4) return is_signed ? ScalarType::i32 : ScalarType::u32;
    if constexpr (sizeof(S) == 8) return is_signed ? ScalarType::i64 : ScalarType::u64;
  }
  return std::nullopt;
}

//! Calls f.template operator()<S>() for each scalar type a property may hold until it
//! returns true; returns whether one did.
template <class F>
bool for_each_scalar(F&& f) {
  return f.template operator()<float>() || f.template operator()<double>() || f.template operator()<bool>() ||
         f.template operator()<char>() || f.template operator()<signed char>() ||
         f.template operator()<unsigned char>() || f.template operator()<short>() ||
         f.template operator()<unsigned short>() || f.template operator()<int>() || f.template operator()<unsigned>() ||
         f.template operator()<long>() || f.template operator()<unsigned long>() ||
         f.template operator()<long long>() || f.template operator()<unsigned long long>();
}

//! Property value type for N components of S: S itself or OpenMesh::VectorT<S, N>.
template <class S, int N>
using value_type_for = std::conditional_t<N == 1, S, OpenMesh::VectorT<S, N>>;

template <class T>
struct value_shape {
  using scalar = T;
  static constexpr int components = 1;
};
template <class S, int N>
struct value_shape<OpenMesh::VectorT<S, N>> {
  using scalar = S;
  static constexpr int components = N;
};

//! Converts one component; colours scale between 0..255 integers and 0..1 reals. Reals
//! out of an integer type's range (or NaN) are clamped (or 0) rather than undefined.
template <class To, class From>
To convert_component(From x, bool color) {
  if constexpr (std::is_same_v<To, bool>) {
    return x != From(0);
  } else if constexpr (std::is_floating_point_v<From> && std::is_integral_v<To>) {
    double v = color ? std::round(std::clamp(double(x), 0.0, 1.0) * 255.0) : double(x);
    if (std::isnan(v)) return To(0);
    v = std::clamp(v, double(std::numeric_limits<To>::lowest()), double(std::numeric_limits<To>::max()));
    return v >= double(std::numeric_limits<To>::max()) ? std::numeric_limits<To>::max() : static_cast<To>(v);
  } else if constexpr (std::is_integral_v<From> && std::is_floating_point_v<To>) {
    return color ? static_cast<To>(double(x) / 255.0) : static_cast<To>(x);
  } else {
    return static_cast<To>(x);
  }
}

//! Reads `prop` into `channel`: channel element i takes OpenMesh element element_of[i]
//! (kNone: zeros). Components beyond the property's are filled with the colour alpha.
template <class T, class Prop>
void read_values(const Prop& prop, const std::vector<int>& element_of, Channel& channel, bool color) {
  using Shape = value_shape<T>;
  using S = typename Shape::scalar;
  with_scalar(channel.scalar, [&]<class C>() {
    C* out = channel.as<C>();
    const auto components = static_cast<std::size_t>(channel.components);
    for (std::size_t i = 0; i < element_of.size(); ++i) {
      if (element_of[i] == kNone) continue;
      const T& value = prop[element_of[i]];
      for (std::size_t k = 0; k < components; ++k) {
        if (k >= std::size_t{Shape::components})
          out[i * components + k] = color ? C(std::is_integral_v<C> ? 255 : 1) : C(0);  // alpha
        else if constexpr (Shape::components == 1)
          out[i * components + k] = convert_component<C>(static_cast<S>(value), color);
        else
          out[i * components + k] = convert_component<C>(value[static_cast<int>(k)], color);
      }
    }
    return true;
  });
}

//! Writes `channel` into `prop`: OpenMesh element j takes channel element source_of[j]
//! (kNone: left as it is). Extra channel components (a colour's alpha) are dropped.
template <class T, class Prop>
void write_values(const Channel& channel, const std::vector<int>& source_of, Prop& prop, bool color) {
  using Shape = value_shape<T>;
  using S = typename Shape::scalar;
  with_scalar(channel.scalar, [&]<class C>() {
    const C* in = channel.as<C>();
    const auto components = static_cast<std::size_t>(channel.components);
    for (std::size_t j = 0; j < source_of.size(); ++j) {
      if (source_of[j] == kNone) continue;
      const C* element = in + static_cast<std::size_t>(source_of[j]) * components;
      if constexpr (Shape::components == 1) {
        prop[static_cast<int>(j)] = convert_component<S>(element[0], color);
      } else {
        T value = prop[static_cast<int>(j)];
        for (int k = 0; k < Shape::components && std::size_t(k) < components; ++k)
          value[k] = convert_component<S>(element[k], color);
        prop[static_cast<int>(j)] = value;
      }
    }
    return true;
  });
}

//! One OpenMesh element kind's property container, seen through the kernel's
//! by-index and by-name accessors.
enum class Kind { vertex, halfedge, edge, face, mesh };

inline const char* kind_name(Kind kind) {
  switch (kind) {
    case Kind::vertex:
      return "vertex";
    case Kind::halfedge:
      return "halfedge";
    case Kind::edge:
      return "edge";
    case Kind::face:
      return "face";
    case Kind::mesh:
      return "mesh";
  }
  return "?";
}

//! The live properties of one kind (OpenMesh leaves a null slot where one was released).
//! M is the mesh type, const or not; the properties come back as const as the mesh.
template <class M>
auto properties_of(M& mesh, Kind kind) {
  using Base = std::conditional_t<std::is_const_v<M>, const OpenMesh::BaseProperty, OpenMesh::BaseProperty>;
  std::vector<Base*> live;
  const auto collect = [&](auto begin, auto end) {
    for (auto it = begin; it != end; ++it)
      if (*it) live.push_back(*it);
  };
  switch (kind) {
    case Kind::vertex:
      collect(mesh.vprops_begin(), mesh.vprops_end());
      break;
    case Kind::halfedge:
      collect(mesh.hprops_begin(), mesh.hprops_end());
      break;
    case Kind::edge:
      collect(mesh.eprops_begin(), mesh.eprops_end());
      break;
    case Kind::face:
      collect(mesh.fprops_begin(), mesh.fprops_end());
      break;
    case Kind::mesh:
      collect(mesh.mprops_begin(), mesh.mprops_end());
      break;
  }
  return live;
}

template <class M>
auto* property_named(M& mesh, Kind kind, const std::string& name) {
  switch (kind) {
    case Kind::vertex:
      return mesh._get_vprop(name);
    case Kind::halfedge:
      return mesh._get_hprop(name);
    case Kind::edge:
      return mesh._get_eprop(name);
    case Kind::face:
      return mesh._get_fprop(name);
    case Kind::mesh:
      break;
  }
  return mesh._get_mprop(name);
}

//! Adds a property of type T named `name` to the container of `kind`.
template <class T, class OMesh>
OpenMesh::BaseProperty& add_property(OMesh& mesh, Kind kind, const std::string& name) {
  if (kind == Kind::vertex) {
    OpenMesh::VPropHandleT<T> handle;
    mesh.add_property(handle, name);
    return mesh.property(handle);
  }
  if (kind == Kind::halfedge) {
    OpenMesh::HPropHandleT<T> handle;
    mesh.add_property(handle, name);
    return mesh.property(handle);
  }
  OpenMesh::FPropHandleT<T> handle;
  mesh.add_property(handle, name);
  return mesh.property(handle);
}

//! Calls f.template operator()<T>(typed) with the property's value type when it is one a
//! channel can hold (a scalar, or a VectorT of 2 to 4 of them); returns false otherwise.
template <class Base, class F>
bool visit_typed(Base& property, F&& f) {
  using Const = std::is_const<Base>;
  return for_each_scalar([&]<class S>() {
    const auto try_type = [&]<int N>() {
      if constexpr (N > 1 && std::is_same_v<S, bool>) {
        return false;
      } else {
        using T = value_type_for<S, N>;
        using Typed = std::conditional_t<Const::value, const OpenMesh::PropertyT<T>, OpenMesh::PropertyT<T>>;
        auto* typed = dynamic_cast<Typed*>(&property);
        if (!typed) return false;
        f.template operator()<T>(*typed);
        return true;
      }
    };
    return try_type.template operator()<1>() || try_type.template operator()<2>() ||
           try_type.template operator()<3>() || try_type.template operator()<4>();
  });
}

//! OpenMesh's standard properties: the soup names they travel under, with their fixed shape.
struct Standard {
  const char* openmesh_name;
  const char* channel;
  Kind kind;
  int components;  //!< channel components (colours: 4)
  bool color;
};
inline constexpr Standard kStandard[] = {
    {"v:normals", "normal", Kind::vertex, 3, false},   {"v:colors", "color", Kind::vertex, 4, true},
    {"v:texcoords2D", "uv", Kind::vertex, 2, false},   {"h:texcoords2D", "uv", Kind::halfedge, 2, false},
    {"h:normals", "normal", Kind::halfedge, 3, false}, {"h:colors", "color", Kind::halfedge, 4, true},
    {"f:normals", "normal", Kind::face, 3, false},     {"f:colors", "color", Kind::face, 4, true},
};

inline const Standard* standard_by_openmesh_name(const std::string& name) {
  for (const Standard& s : kStandard)
    if (name == s.openmesh_name) return &s;
  return nullptr;
}

inline Domain domain_of(Kind kind) {
  return kind == Kind::vertex ? Domain::vertex : kind == Kind::face ? Domain::face : Domain::corner;
}

//! Properties that are OpenMesh's bookkeeping rather than data: positions, status flags.
inline bool is_bookkeeping(const std::string& name) { return name == "v:points" || name.ends_with(":status"); }

//! Asks OpenMesh for the standard property a channel maps to, and returns it.
template <class OMesh>
OpenMesh::BaseProperty* request_standard(OMesh& mesh, const Standard& s) {
  const std::string name = s.openmesh_name;
  if (name == "v:normals") mesh.request_vertex_normals();
  if (name == "v:colors") mesh.request_vertex_colors();
  if (name == "v:texcoords2D") mesh.request_vertex_texcoords2D();
  if (name == "h:texcoords2D") mesh.request_halfedge_texcoords2D();
  if (name == "h:normals") mesh.request_halfedge_normals();
  if (name == "h:colors") mesh.request_halfedge_colors();
  if (name == "f:normals") mesh.request_face_normals();
  if (name == "f:colors") mesh.request_face_colors();
  return property_named(mesh, s.kind, name);
}

//! Quiets OpenMesh's error stream (add_face prints each refusal) or collects it for a message.
class OpenMeshMessages {
 public:
  explicit OpenMeshMessages(bool collect) {
    ::omerr().flush();
    was_on_cerr_ = ::omerr().disconnect(std::cerr);
    if (collect) ::omerr().connect(collected_);
    log_enabled_ = ::omlog().is_enabled();
    ::omlog().disable();
  }
  ~OpenMeshMessages() {
    ::omerr().flush();
    ::omerr().disconnect(collected_);
    if (was_on_cerr_) ::omerr().connect(std::cerr);
    if (log_enabled_) ::omlog().enable();
  }
  OpenMeshMessages(const OpenMeshMessages&) = delete;
  OpenMeshMessages& operator=(const OpenMeshMessages&) = delete;

  //! What OpenMesh said, on one line.
  std::string text() {
    ::omerr().flush();
    std::string s = collected_.str();
    std::replace(s.begin(), s.end(), '\n', ' ');
    while (!s.empty() && s.back() == ' ') s.pop_back();
    return s;
  }

 private:
  std::ostringstream collected_;
  bool was_on_cerr_ = false;
  bool log_enabled_ = false;
};

}  // namespace detail

//! OpenMesh mesh -> soup (see the contract at the top). Throws Error when the mesh has
//! deleted elements still in it (call garbage_collection() first).
template <class OMesh>
Soup to_soup(const OMesh& mesh, std::vector<SkippedProperty>* skipped = nullptr) {
  using namespace detail;
  const auto has_deleted = [&](auto range, bool has_status) {
    if (!has_status) return false;
    for (auto handle : range)
      if (mesh.status(handle).deleted()) return true;
    return false;
  };
  if (has_deleted(mesh.all_vertices(), mesh.has_vertex_status()) ||
      has_deleted(mesh.all_faces(), mesh.has_face_status()))
    throw Error("openmesh: the mesh has deleted elements; call garbage_collection() first");

  Soup soup;
  soup.positions.reserve(mesh.n_vertices());
  for (auto vertex : mesh.all_vertices()) {
    const auto& p = mesh.point(vertex);
    soup.positions.push_back(Point{{static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2])}});
  }
  // Corner k of the soup is the half-edge that points to it.
  std::vector<int> corner_halfedge;
  soup.face_sizes.reserve(mesh.n_faces());
  for (auto face : mesh.all_faces()) {
    std::uint32_t size = 0;
    for (auto halfedge : mesh.fh_range(face)) {
      soup.corners.push_back(static_cast<std::uint32_t>(mesh.to_vertex_handle(halfedge).idx()));
      corner_halfedge.push_back(halfedge.idx());
      ++size;
    }
    soup.face_sizes.push_back(size);
  }
  const auto identity = [](std::size_t n) {
    std::vector<int> map(n);
    for (std::size_t i = 0; i < n; ++i) map[i] = static_cast<int>(i);
    return map;
  };
  const std::vector<int> vertex_map = identity(mesh.n_vertices()), face_map = identity(mesh.n_faces());
  const auto element_of = [&](Domain domain) -> const std::vector<int>& {
    return domain == Domain::vertex ? vertex_map : domain == Domain::face ? face_map : corner_halfedge;
  };
  const auto skip = [&](const std::string& name, Kind kind, std::string reason) {
    if (skipped) skipped->push_back({name, kind_name(kind), std::move(reason)});
  };

  // Standard properties first, so a custom one cannot take their names.
  for (const Standard& s : kStandard) {
    const OpenMesh::BaseProperty* property = property_named(mesh, s.kind, s.openmesh_name);
    if (!property) continue;
    const bool carried = visit_typed(*property, [&]<class T>(const OpenMesh::PropertyT<T>& typed) {
      using S = typename value_shape<T>::scalar;
      const ScalarType scalar = s.color && std::is_integral_v<S> ? ScalarType::u8 : ScalarType::f32;
      Channel& channel = soup.add_channel(s.channel, domain_of(s.kind), scalar, s.components);
      read_values<T>(typed, element_of(channel.domain), channel, s.color);
    });
    if (!carried) skip(s.openmesh_name, s.kind, "its value type has no channel type");
  }
  for (Kind kind : {Kind::vertex, Kind::halfedge, Kind::face, Kind::edge, Kind::mesh}) {
    for (const OpenMesh::BaseProperty* live : properties_of(mesh, kind)) {
      const OpenMesh::BaseProperty& property = *live;
      const std::string& name = property.name();
      if (is_bookkeeping(name) || standard_by_openmesh_name(name)) continue;
      const bool unnamed = name.starts_with("<");
      const bool carried =
          !unnamed && (kind == Kind::vertex || kind == Kind::halfedge || kind == Kind::face) &&
          !soup.find(name, domain_of(kind)) && visit_typed(property, [&]<class T>(const OpenMesh::PropertyT<T>& typed) {
            using Shape = value_shape<T>;
            Channel& channel =
                soup.add_channel(name, domain_of(kind), *scalar_type_of<typename Shape::scalar>(), Shape::components);
            read_values<T>(typed, element_of(channel.domain), channel, false);
          });
      if (carried) continue;
      // OpenMesh's own per-element data (the traits' attributes) is unnamed and untyped for us.
      const bool typed_for_us = visit_typed(property, []<class T>(const OpenMesh::PropertyT<T>&) {});
      if (unnamed && !typed_for_us) continue;
      if (unnamed)
        skip(name, kind, "it has no name to carry it by");
      else if (kind == Kind::edge || kind == Kind::mesh)
        skip(name, kind, std::string("a soup has no ") + kind_name(kind) + " channels");
      else if (!typed_for_us)
        skip(name, kind, "its value type has no channel type (" + property.internal_type_name() + ")");
      else
        skip(name, kind, "a channel of that name is there already");
    }
  }
  return soup;
}

//! Soup -> OpenMesh mesh, replacing the mesh's elements (its property declarations stay, and
//! a channel fills the property of its name, converting values to the property's type). See
//! the contract at the top: every face arrives. Throws Error on soups Soup::check() refuses.
template <class OMesh>
FromSoupReport from_soup(const Soup& soup, OMesh& mesh, const FromSoupOptions& options = {}) {
  using namespace detail;
  FromSoupReport report;
  BuildOptions build_options;
  build_options.orient = options.orient;
  BuildResult built = build(soup, build_options);
  report.build = built.report;
  report.skipped_faces = built.maps.skipped_faces;
  // The manifold soup: build()'s copies kept apart, vertex i < n the soup's vertex i, then copies.
  ExtractOptions keep_copies;
  keep_copies.restore_source = false;
  const Soup manifold = extract(built.mesh, keep_copies);
  const std::vector<std::uint32_t>& manifold_source = built.maps.vertex_source;

  mesh.clear();
  // OpenMesh vertex -> manifold vertex; half-edge -> manifold corner; face -> manifold face.
  std::vector<int> vertex_of(manifold.n_vertices()), corner_of, face_of;
  for (std::size_t v = 0; v < manifold.n_vertices(); ++v) {
    const Point& p = manifold.positions[v];
    mesh.add_vertex(typename OMesh::Point(p[0], p[1], p[2]));
    vertex_of[v] = static_cast<int>(v);
  }
  const std::vector<std::size_t> offsets = manifold.face_offsets();
  std::vector<typename OMesh::VertexHandle> handles;
  {
    OpenMeshMessages quiet(false);
    for (std::size_t f = 0; f < manifold.n_faces(); ++f) {
      const std::uint32_t* corners = manifold.corners.data() + offsets[f];
      const std::size_t size = manifold.face_sizes[f];
      handles.clear();
      for (std::size_t k = 0; k < size; ++k) handles.emplace_back(static_cast<int>(corners[k]));
      const std::size_t faces_before = mesh.n_faces();
      if (!mesh.add_face(handles).is_valid()) {
        // The rare face OpenMesh still refuses (its order of adding faces can strand a gap):
        // it gets copies of its own vertices, so it arrives all the same.
        for (std::size_t k = 0; k < size; ++k) {
          handles[k] = mesh.add_vertex(mesh.point(handles[k]));
          vertex_of.push_back(static_cast<int>(corners[k]));
        }
        if (!mesh.add_face(handles).is_valid()) throw Error("openmesh: add_face refused a face of fresh vertices");
      }
      for (std::size_t added = faces_before; added < mesh.n_faces(); ++added) face_of.push_back(static_cast<int>(f));
    }
  }
  corner_of.assign(mesh.n_halfedges(), kNone);
  for (auto face : mesh.all_faces()) {
    const std::size_t f = static_cast<std::size_t>(face_of[static_cast<std::size_t>(face.idx())]);
    for (auto halfedge : mesh.fh_range(face)) {
      const auto target =
          static_cast<std::uint32_t>(vertex_of[static_cast<std::size_t>(mesh.to_vertex_handle(halfedge).idx())]);
      for (std::size_t k = 0; k < manifold.face_sizes[f]; ++k)
        if (manifold.corners[offsets[f] + k] == target)
          corner_of[static_cast<std::size_t>(halfedge.idx())] = static_cast<int>(offsets[f] + k);
    }
  }

  report.vertex_source.reserve(mesh.n_vertices());
  for (int v : vertex_of) report.vertex_source.push_back(manifold_source[static_cast<std::size_t>(v)]);
  report.vertex_copies = mesh.n_vertices() - soup.n_vertices();
  for (int f : face_of) report.face_source.push_back(built.maps.face_source[static_cast<std::size_t>(f)]);

  for (const Channel& channel : manifold.channels) {
    const Kind kind = channel.domain == Domain::vertex ? Kind::vertex
                      : channel.domain == Domain::face ? Kind::face
                                                       : Kind::halfedge;
    const std::vector<int>& source_of = kind == Kind::vertex ? vertex_of : kind == Kind::face ? face_of : corner_of;
    const Standard* standard = nullptr;
    for (const Standard& s : kStandard)
      if (channel.name == s.channel && kind == s.kind &&
          (channel.components == s.components || (s.color && channel.components == 3)))
        standard = &s;
    OpenMesh::BaseProperty* property =
        standard ? request_standard(mesh, *standard) : property_named(mesh, kind, channel.name);
    if (!property && channel.components >= 1 && channel.components <= 4) {
      with_scalar(channel.scalar, [&]<class C>() {
        const auto add = [&]<int N>() {
          if (channel.components == N) property = &add_property<value_type_for<C, N>>(mesh, kind, channel.name);
        };
        add.template operator()<1>();
        add.template operator()<2>();
        add.template operator()<3>();
        add.template operator()<4>();
        return true;
      });
    }
    const bool color = standard && standard->color;
    std::string reason = "OpenMesh holds at most 4 components of a custom property";
    const bool carried = property && visit_typed(*property, [&]<class T>(OpenMesh::PropertyT<T>& typed) {
                           if (value_shape<T>::components != channel.components && !color) {
                             reason = "the mesh's property '" + channel.name + "' has " +
                                      std::to_string(value_shape<T>::components) + " components, the channel " +
                                      std::to_string(channel.components);
                             return;
                           }
                           write_values<T>(channel, source_of, typed, color);
                           reason.clear();
                         });
    if (property && !carried) reason = "the mesh's property of that name has a type no channel maps to";
    if (!reason.empty()) report.skipped.push_back({channel.name, domain_name(channel.domain), reason});
  }
  return report;
}

//! The mesh type .om files are read into and written from: polygons, float positions, RGBA
//! colours (though OpenMesh 9's .om writer keeps RGB only: alpha reads back as 255).
struct OmFileTraits : OpenMesh::DefaultTraits {
  typedef OpenMesh::Vec4uc Color;
};
using OmFileMesh = OpenMesh::PolyMesh_ArrayKernelT<OmFileTraits>;

//! Reads an OpenMesh .om file with OpenMesh's reader. Throws Error naming the file and the
//! reason on anything that is not a readable .om file.
inline Soup read_om(const std::string& path, std::vector<SkippedProperty>* skipped = nullptr) {
  std::uint64_t vertices = 0, faces = 0;
  {
    // OpenMesh's reader trusts the header's counts; refuse what is plainly not an .om file first.
    std::ifstream file(path, std::ios::binary | std::ios::ate);
    if (!file) throw Error("cannot open " + path);
    const auto size = static_cast<std::uint64_t>(file.tellg());
    file.seekg(0);
    unsigned char header[16] = {};
    file.read(reinterpret_cast<char*>(header), sizeof header);
    if (size < sizeof header || header[0] != 'O' || header[1] != 'M')
      throw Error(path + ": not an OpenMesh .om file (it does not start with an 'OM' header)");
    const auto count = [&](int at) {
      return std::uint64_t(header[at]) | std::uint64_t(header[at + 1]) << 8 | std::uint64_t(header[at + 2]) << 16 |
             std::uint64_t(header[at + 3]) << 24;
    };
    vertices = count(4);
    faces = count(8);
    const std::uint64_t edges = count(12);
    if (vertices + faces + edges > size)
      throw Error(path + ": the header promises " + std::to_string(vertices) + " vertices, " + std::to_string(faces) +
                  " faces and " + std::to_string(edges) + " edges, more than a file of " + std::to_string(size) +
                  " bytes can hold");
  }
  OmFileMesh mesh;
  mesh.request_vertex_normals();
  mesh.request_vertex_colors();
  mesh.request_vertex_texcoords2D();
  mesh.request_halfedge_texcoords2D();
  mesh.request_face_normals();
  mesh.request_face_colors();
  OpenMesh::IO::Options wanted = OpenMesh::IO::Options::VertexNormal | OpenMesh::IO::Options::VertexColor |
                                 OpenMesh::IO::Options::VertexTexCoord | OpenMesh::IO::Options::FaceTexCoord |
                                 OpenMesh::IO::Options::FaceNormal | OpenMesh::IO::Options::FaceColor |
                                 OpenMesh::IO::Options::ColorAlpha;
  OpenMesh::IO::Options found = wanted;
  bool read = false;
  detail::OpenMeshMessages messages(true);
  try {
    read = OpenMesh::IO::read_mesh(mesh, path, found);
  } catch (const std::exception& e) {
    throw Error(path + ": OpenMesh could not read it: " + e.what());
  }
  if (!read) {
    const std::string said = messages.text();
    throw Error(path + ": OpenMesh could not read it" + (said.empty() ? std::string() : ": " + said));
  }
  // OpenMesh stops quietly at the end of a file cut short.
  if (mesh.n_vertices() != vertices || mesh.n_faces() != faces)
    throw Error(path + ": cut short: the header promises " + std::to_string(vertices) + " vertices and " +
                std::to_string(faces) + " faces, the file holds " + std::to_string(mesh.n_vertices()) + " and " +
                std::to_string(mesh.n_faces()));
  // Drop the standard properties the file did not have, so they do not become zero channels.
  if (!found.vertex_has_normal()) mesh.release_vertex_normals();
  if (!found.vertex_has_color()) mesh.release_vertex_colors();
  if (!found.vertex_has_texcoord()) mesh.release_vertex_texcoords2D();
  if (!found.face_has_texcoord()) mesh.release_halfedge_texcoords2D();
  if (!found.face_has_normal()) mesh.release_face_normals();
  if (!found.face_has_color()) mesh.release_face_colors();
  return to_soup(mesh, skipped);
}

//! Writes a soup as an OpenMesh .om file through from_soup() (so every face is written) and
//! OpenMesh's writer; channels become persistent properties. Throws Error naming the file.
inline FromSoupReport write_om(const Soup& soup, const std::string& path) {
  OmFileMesh mesh;
  FromSoupReport report = from_soup(soup, mesh);
  OpenMesh::IO::Options options = OpenMesh::IO::Options::Binary;
  if (mesh.has_vertex_normals()) options += OpenMesh::IO::Options::VertexNormal;
  if (mesh.has_vertex_colors()) options += OpenMesh::IO::Options::VertexColor;
  if (mesh.has_vertex_texcoords2D()) options += OpenMesh::IO::Options::VertexTexCoord;
  if (mesh.has_halfedge_texcoords2D()) options += OpenMesh::IO::Options::FaceTexCoord;
  if (mesh.has_face_normals()) options += OpenMesh::IO::Options::FaceNormal;
  if (mesh.has_face_colors()) options += OpenMesh::IO::Options::FaceColor;
  if (mesh.has_vertex_colors() || mesh.has_face_colors()) options += OpenMesh::IO::Options::ColorAlpha;
  for (detail::Kind kind : {detail::Kind::vertex, detail::Kind::halfedge, detail::Kind::face})
    for (OpenMesh::BaseProperty* property : detail::properties_of(mesh, kind)) {
      const std::string& name = property->name();
      if (!name.starts_with("<") && !detail::is_bookkeeping(name) && !detail::standard_by_openmesh_name(name))
        property->set_persistent(true);
    }
  detail::OpenMeshMessages messages(true);
  bool written = false;
  try {
    written = OpenMesh::IO::write_mesh(mesh, path, options);
  } catch (const std::exception& e) {
    throw Error("cannot write " + path + ": " + e.what());
  }
  if (!written) {
    const std::string said = messages.text();
    throw Error("cannot write " + path + (said.empty() ? std::string() : ": " + said));
  }
  return report;
}

}  // namespace hedge::openmesh
