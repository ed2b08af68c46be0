// hedge._native: the catalogue and run_operation() for the Blender add-on, on numpy arrays.
// Python speaks Soup as a dict of arrays; the mesh work runs without the GIL, either
// synchronously (redo, scripts) or on a worker thread (Job) that a modal operator polls.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstring>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "hedge/build.h"
#include "hedge/catalogue.h"
#include "hedge/error.h"
#include "hedge/io.h"

namespace py = pybind11;
using namespace hedge;

namespace {

// ---- catalogue ------------------------------------------------------------------------------

py::dict param_dict(const ParamSpec& p) {
  py::dict d;
  d["id"] = p.id;
  d["label"] = p.label;
  d["help"] = p.help;
  d["type"] = param_type_name(p.type);
  d["default"] = std::visit([](const auto& v) -> py::object { return py::cast(v); }, p.default_value);
  // Integer and real: no "max" (None) means no upper limit.
  d["min"] = p.range.min;
  d["max"] = p.range.max ? py::cast(*p.range.max) : py::none();
  d["choices"] = p.choices;
  d["range_text"] = p.range_text();
  return d;
}

py::list catalogue_list() {
  py::list ops;
  for (const Operation& op : catalogue()) {
    py::dict d;
    d["id"] = op.id;
    d["title"] = op.title;
    d["category"] = category_name(op.category);
    d["results"] = op.results;
    d["help"] = op.help;
    d["changes_mesh"] = op.changes_mesh;
    py::list params;
    for (const auto& p : op.params) params.append(param_dict(p));
    d["params"] = params;
    ops.append(d);
  }
  return ops;
}

// ---- numpy <-> Soup -------------------------------------------------------------------------

ScalarType scalar_of(const py::dtype& dt) {
  const char kind = dt.kind();
  const auto size = dt.itemsize();
  if (kind == 'f' && size == 4) return ScalarType::f32;
  if (kind == 'f' && size == 8) return ScalarType::f64;
  if (kind == 'i' || kind == 'b') {
    if (size == 1) return ScalarType::i8;
    if (size == 2) return ScalarType::i16;
    if (size == 4) return ScalarType::i32;
    if (size == 8) return ScalarType::i64;
  }
  if (kind == 'u') {
    if (size == 1) return ScalarType::u8;
    if (size == 2) return ScalarType::u16;
    if (size == 4) return ScalarType::u32;
    if (size == 8) return ScalarType::u64;
  }
  throw Error("unsupported array type '" + std::string(py::str(py::handle(dt))) + "'");
}

py::dtype dtype_of(ScalarType s) {
  switch (s) {
    case ScalarType::f32:
      return py::dtype::of<float>();
    case ScalarType::f64:
      return py::dtype::of<double>();
    case ScalarType::i8:
      return py::dtype::of<std::int8_t>();
    case ScalarType::u8:
      return py::dtype::of<std::uint8_t>();
    case ScalarType::i16:
      return py::dtype::of<std::int16_t>();
    case ScalarType::u16:
      return py::dtype::of<std::uint16_t>();
    case ScalarType::i32:
      return py::dtype::of<std::int32_t>();
    case ScalarType::u32:
      return py::dtype::of<std::uint32_t>();
    case ScalarType::i64:
      return py::dtype::of<std::int64_t>();
    case ScalarType::u64:
      return py::dtype::of<std::uint64_t>();
  }
  return py::dtype::of<float>();
}

Domain domain_of(const std::string& name) {
  if (name == "vertex") return Domain::vertex;
  if (name == "face") return Domain::face;
  if (name == "corner") return Domain::corner;
  throw Error("unknown channel domain '" + name + "' (vertex, face or corner)");
}

// A C-contiguous view of any array-like; the buffer is read in place (one memcpy into the Soup).
py::array contiguous(const py::handle& obj) { return py::array::ensure(obj, py::array::c_style); }

// Copies a's elements into out, unless they are there already (a is a view of out). A `fixed`
// vector (a SoupBuffers' own, which Python may hold views of) is never reallocated.
template <class T>
void take(const char* key, const py::array& a, std::vector<T>& out, bool fixed) {
  const auto* first = static_cast<const T*>(a.data());
  const auto n = static_cast<std::size_t>(a.nbytes()) / sizeof(T);
  if (first == out.data() && n == out.size()) return;
  if (fixed && n != out.size())
    throw Error(std::string(key) + ": " + std::to_string(n) + " elements, the buffers hold " +
                std::to_string(out.size()));
  out.assign(first, first + n);  // one copy; resize() then memcpy would write every element twice
}

// Blocks handed to Python for channels (SoupBuffers.zeros), not yet in a soup.
using Blocks = std::vector<std::vector<std::byte>>;

// Fills `soup` from a mesh dict. An array that is already the soup's own (positions, face sizes,
// corners), or one of `spare`'s blocks (a channel), is taken where it lies; any other is copied.
// Given `spare` (the soup is a SoupBuffers'), no memory the soup or `spare` holds is freed.
void read_soup(const py::dict& mesh, Soup& soup, Blocks* spare) {
  {
    py::array p = contiguous(mesh["positions"]);
    if (!p || p.dtype().kind() != 'f' || p.itemsize() != 4) throw Error("positions must be float32");
    if (p.size() % 3) throw Error("positions: expected rows of 3");
    static_assert(sizeof(Point) == 3 * sizeof(float));
    take("positions", p, soup.positions, spare != nullptr);
  }
  auto indices = [&](const char* key, std::vector<std::uint32_t>& out) {
    py::array a = contiguous(mesh[key]);
    if (!a || (a.dtype().kind() != 'i' && a.dtype().kind() != 'u') || a.itemsize() != 4)
      throw Error(std::string(key) + " must be int32 or uint32");
    take(key, a, out, spare != nullptr);
  };
  indices("face_sizes", soup.face_sizes);
  indices("corners", soup.corners);
  if (spare)  // channels taken before go back with the blocks, so that none is ever freed
    for (Channel& c : soup.channels) spare->push_back(std::move(c.data));
  soup.channels.clear();
  if (mesh.contains("channels")) {
    for (const py::handle& item : mesh["channels"]) {
      auto t = item.cast<py::tuple>();
      if (t.size() != 3) throw Error("a channel is (name, domain, array)");
      Channel c;
      c.name = t[0].cast<std::string>();
      c.domain = domain_of(t[1].cast<std::string>());
      py::array a = contiguous(t[2]);
      c.scalar = scalar_of(a.dtype());
      const std::size_t n = soup.domain_size(c.domain);
      c.components = a.ndim() >= 2 ? static_cast<int>(a.size() / std::max<py::ssize_t>(a.shape(0), 1))
                                   : (n ? static_cast<int>(static_cast<std::size_t>(a.size()) / n) : 1);
      if (c.components < 1) c.components = 1;
      const auto* first = static_cast<const std::byte*>(a.data());
      const auto bytes = static_cast<std::size_t>(a.nbytes());
      auto block = spare ? std::find_if(spare->begin(), spare->end(),
                                        [&](const auto& b) { return b.data() == first && b.size() == bytes; })
                         : Blocks::iterator{};
      if (spare && block != spare->end()) {
        c.data = std::move(*block);
        spare->erase(block);
      } else {
        c.data.assign(first, first + bytes);
      }
      soup.channels.push_back(std::move(c));
    }
  }
  soup.check();
}

Soup soup_from(const py::dict& mesh) {
  Soup soup;
  read_soup(mesh, soup, nullptr);
  return soup;
}

// Arrays that Python fills where they lie (Blender's foreach_get writes straight into them)
// and an operation then reads there: a mesh dict naming these buffers under "buffers" crosses
// into the native side without copying them. Its other arrays (a reordered copy, a computed
// channel) are copied as always. The views handed out keep the buffers alive, and no block
// is freed before the buffers are, so a view never outlives its memory.
class SoupBuffers {
 public:
  SoupBuffers(std::size_t vertices, std::size_t faces, std::size_t corners) {
    soup_.positions.resize(vertices);
    soup_.face_sizes.resize(faces);
    soup_.corners.resize(corners);
  }
  // The soup the mesh dict describes, refused while an operation reads these buffers.
  void read(const py::dict& mesh) {
    if (readers_.load() > 0) throw Error("the mesh's buffers are in use by a running operation");
    read_soup(mesh, soup_, &spare_);
  }
  const Soup& soup() const { return soup_; }
  Soup& soup() { return soup_; }
  std::byte* block(std::size_t bytes) { return spare_.emplace_back(bytes).data(); }
  std::atomic<int>& readers() { return readers_; }

 private:
  Soup soup_;
  Blocks spare_;
  std::atomic<int> readers_{0};
};

// A numpy view of `data`, which lives as long as `owner` (the SoupBuffers) does.
template <class T>
py::array view(T* data, std::vector<py::ssize_t> shape, const py::object& owner,
               const py::dtype& dt = py::dtype::of<T>()) {
  return py::array(dt, std::move(shape), {}, data, owner);
}

// The buffers an operation reads, counted as read until it lets go of them.
class Lease {
 public:
  Lease() = default;
  explicit Lease(std::shared_ptr<SoupBuffers> b) : buffers_(std::move(b)) { ++buffers_->readers(); }
  Lease(Lease&& o) noexcept : buffers_(std::move(o.buffers_)) {}
  Lease& operator=(Lease&&) = delete;
  ~Lease() {
    if (buffers_) --buffers_->readers();
  }
  const SoupBuffers* get() const { return buffers_.get(); }

 private:
  std::shared_ptr<SoupBuffers> buffers_;
};

// Hands a vector to numpy without copying: the array owns it through a capsule.
template <class T>
py::array adopt(std::vector<T>&& v, py::dtype dt, std::vector<py::ssize_t> shape) {
  auto* owner = new std::vector<T>(std::move(v));
  py::capsule free_owner(owner, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  std::vector<py::ssize_t> strides(shape.size());
  py::ssize_t stride = dt.itemsize();
  for (std::size_t i = shape.size(); i-- > 0;) {
    strides[i] = stride;
    stride *= shape[i];
  }
  return py::array(dt, shape, strides, owner->data(), free_owner);
}

py::dict soup_to(Soup&& soup) {
  py::dict d;
  const auto nv = static_cast<py::ssize_t>(soup.positions.size());
  d["positions"] = adopt(std::move(soup.positions), py::dtype::of<float>(), {nv, 3});
  const auto nf = static_cast<py::ssize_t>(soup.face_sizes.size());
  d["face_sizes"] = adopt(std::move(soup.face_sizes), py::dtype::of<std::int32_t>(), {nf});
  const auto nc = static_cast<py::ssize_t>(soup.corners.size());
  d["corners"] = adopt(std::move(soup.corners), py::dtype::of<std::int32_t>(), {nc});
  py::list channels;
  for (Channel& c : soup.channels) {
    const auto n = static_cast<py::ssize_t>(c.count());
    const py::dtype dt = dtype_of(c.scalar);
    std::vector<py::ssize_t> shape = {n};
    if (c.components > 1) shape.push_back(c.components);
    channels.append(py::make_tuple(c.name, domain_name(c.domain), adopt(std::move(c.data), dt, shape)));
  }
  d["channels"] = channels;
  return d;
}

py::object value_to_py(const Value& v) {
  return std::visit([](const auto& x) -> py::object { return py::cast(x); }, v);
}

py::dict report_to(const OperationReport& r) {
  py::dict d;
  for (const auto& [key, value] : r.entries) d[py::str(key)] = value_to_py(value);
  d["messages"] = r.messages;
  return d;
}

std::map<std::string, Value> values_from(const Operation& op, const py::dict& params) {
  std::map<std::string, Value> given;
  for (const auto& [k, v] : params) {
    const std::string id = py::str(k);
    const ParamSpec* spec = op.find_param(id);
    if (py::isinstance<py::bool_>(v))
      given[id] = v.cast<bool>();
    else if (py::isinstance<py::int_>(v))
      given[id] = v.cast<std::int64_t>();
    else if (py::isinstance<py::float_>(v))
      given[id] = v.cast<double>();
    else if (py::isinstance<py::str>(v))
      given[id] = v.cast<std::string>();
    else if (spec)
      throw Error(op.id + ": parameter " + id + " must be " + spec->range_text());
    else
      given[id] = std::string(py::str(v));  // resolve_params names the unknown id
  }
  return given;
}

// ---- running --------------------------------------------------------------------------------

struct Prepared {
  const Operation* op;
  Soup copied;  // the mesh dict's arrays, copied
  Lease lease;  // or the buffers that hold them, read where they lie
  ParamValues values;
  const Soup& soup() const { return lease.get() ? lease.get()->soup() : copied; }
};

Prepared prepare(const std::string& op_id, const py::dict& mesh, const py::dict& params) {
  const Operation& op = find_operation(op_id);
  ParamValues values = resolve_params(op, values_from(op, params));  // refused before any work
  if (mesh.contains("buffers")) {
    auto buffers = mesh["buffers"].cast<std::shared_ptr<SoupBuffers>>();
    buffers->read(mesh);
    return {&op, Soup{}, Lease(std::move(buffers)), std::move(values)};
  }
  return {&op, soup_from(mesh), Lease{}, std::move(values)};
}

py::tuple finish(RunResult&& result, const Operation& op) {
  py::object soup = op.changes_mesh ? py::object(soup_to(std::move(result.soup))) : py::none();
  return py::make_tuple(soup, report_to(result.report));
}

// Synchronous run; `progress` is None or callable(fraction, stage) -> bool (False cancels).
py::tuple run(const std::string& op_id, const py::dict& mesh, const py::dict& params, const py::object& progress) {
  Prepared p = prepare(op_id, mesh, params);
  RunResult result;
  {
    Progress::Callback cb;
    if (!progress.is_none())
      cb = [&progress](double fraction, const std::string& stage) {
        py::gil_scoped_acquire gil;
        py::object r = progress(fraction, stage);
        return r.is_none() || r.cast<bool>();
      };
    Progress prog(cb);
    py::gil_scoped_release nogil;
    result = run_operation(*p.op, p.soup(), p.values, prog);
  }
  return finish(std::move(result), *p.op);
}

// An operation on a worker thread: the modal operator polls progress(), may cancel(), and
// collects result() once done() (which rethrows the operation's error).
class Job {
 public:
  Job(const std::string& op_id, const py::dict& mesh, const py::dict& params)
      : prepared_(prepare(op_id, mesh, params)) {
    thread_ = std::thread([this] {
      Progress prog([this](double fraction, const std::string& stage) {
        {
          std::lock_guard lock(mutex_);
          fraction_ = fraction;
          stage_ = stage;
        }
        return !cancel_.load();
      });
      try {
        result_ = run_operation(*prepared_.op, prepared_.soup(), prepared_.values, prog);
      } catch (...) {
        error_ = std::current_exception();
      }
      {
        std::lock_guard lock(mutex_);
        done_.store(true);
      }
      finished_.notify_all();
    });
  }
  ~Job() {
    cancel_.store(true);
    if (thread_.joinable()) {
      py::gil_scoped_release nogil;
      thread_.join();
    }
  }
  bool done() const { return done_.load(); }
  // Until done or `seconds` have passed, without the GIL: the caller's thread meanwhile reads
  // what the operation does not need, and wakes as soon as it is done.
  bool wait(double seconds) {
    py::gil_scoped_release nogil;
    std::unique_lock lock(mutex_);
    finished_.wait_for(lock, std::chrono::duration<double>(seconds), [this] { return done_.load(); });
    return done_.load();
  }
  void cancel() { cancel_.store(true); }
  py::tuple progress() {
    std::lock_guard lock(mutex_);
    return py::make_tuple(fraction_, stage_);
  }
  py::tuple result() {
    {
      py::gil_scoped_release nogil;
      if (thread_.joinable()) thread_.join();
    }
    if (error_) std::rethrow_exception(error_);
    if (!result_) throw Error("the result was already taken");
    RunResult r = std::move(*result_);
    result_.reset();
    return finish(std::move(r), *prepared_.op);
  }

 private:
  Prepared prepared_;
  std::thread thread_;
  std::atomic<bool> done_{false}, cancel_{false};
  std::mutex mutex_;
  std::condition_variable finished_;
  double fraction_ = 0;
  std::string stage_;
  std::optional<RunResult> result_;
  std::exception_ptr error_;
};

// build() then extract() with nothing in between: the exchange's no-op round trip.
py::dict build_extract(const py::dict& mesh) {
  Soup soup = soup_from(mesh);
  Soup out;
  {
    py::gil_scoped_release nogil;
    out = extract(build(soup).mesh);
  }
  return soup_to(std::move(out));
}

py::dict read_file(const std::string& path) {
  Soup soup;
  {
    py::gil_scoped_release nogil;
    soup = read_mesh(path);
  }
  return soup_to(std::move(soup));
}

void write_file(const py::dict& mesh, const std::string& path) {
  Soup soup = soup_from(mesh);
  py::gil_scoped_release nogil;
  write_mesh(soup, path);
}

// Sets the Python error of a translated exception: py::set_error where pybind11 has it
// (2.12+; 3.x deprecates calling the exception object), the C API before (Debian 12's 2.10).
void raise_error(const py::handle& type, const char* message) {
#if PYBIND11_VERSION_HEX >= 0x020C0000
  py::set_error(type, message);
#else
  PyErr_SetString(type.ptr(), message);
#endif
}

}  // namespace

PYBIND11_MODULE(_native, m) {
  m.doc() = "hedge half-edge mesh processing: the operation catalogue on numpy arrays";
  // The exception types live as long as the process: released handles, so no static
  // destructor touches Python after the host has finalized it.
  static const py::handle error_type = py::exception<Error>(m, "Error", PyExc_RuntimeError).release();
  static const py::handle cancelled_type = py::exception<Cancelled>(m, "Cancelled", error_type).release();
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const Cancelled& e) {
      raise_error(cancelled_type, e.what());
    } catch (const Error& e) {
      raise_error(error_type, e.what());
    } catch (const std::bad_alloc&) {
      raise_error(error_type, "out of memory");
    }
  });
  m.def("catalogue", &catalogue_list, "Every operation with its parameters, in menu order.");
  m.def(
      "categories",
      [] {
        std::vector<std::string> names;
        for (Category c : kCategories) names.push_back(category_name(c));
        return names;
      },
      "The categories' names, in the order panels and menus list them.");
  m.def("run", &run, py::arg("operation"), py::arg("mesh"), py::arg("params") = py::dict(),
        py::arg("progress") = py::none(),
        "Runs one operation on a mesh dict (positions, face_sizes, corners, channels); returns "
        "(mesh dict or None, report dict). Raises Error, or Cancelled when progress returns False.");
  m.def("build_extract", &build_extract, py::arg("mesh"),
        "build() and extract() with nothing in between (the no-op round trip).");
  m.def("read_mesh", &read_file, py::arg("path"), "Reads OFF/OBJ/PLY/STL with hedge's reader into a mesh dict.");
  m.def("write_mesh", &write_file, py::arg("mesh"), py::arg("path"), "Writes a mesh dict with hedge's writer.");
  py::class_<SoupBuffers, std::shared_ptr<SoupBuffers>>(
      m, "SoupBuffers",
      "Arrays to fill in place for a mesh dict (positions, face_sizes, corners, and blocks for "
      "channels); a dict naming them under \"buffers\" is read where they lie, not copied.")
      .def(py::init<std::size_t, std::size_t, std::size_t>(), py::arg("vertices"), py::arg("faces"), py::arg("corners"))
      .def_property_readonly("positions",
                             [](py::object self) {
                               auto& p = self.cast<SoupBuffers&>().soup().positions;
                               return view(reinterpret_cast<float*>(p.data()), {py::ssize_t(p.size()), 3}, self);
                             })
      .def_property_readonly("face_sizes",
                             [](py::object self) {
                               auto& f = self.cast<SoupBuffers&>().soup().face_sizes;
                               return view(f.data(), {py::ssize_t(f.size())}, self, py::dtype::of<std::int32_t>());
                             })
      .def_property_readonly("corners",
                             [](py::object self) {
                               auto& c = self.cast<SoupBuffers&>().soup().corners;
                               return view(c.data(), {py::ssize_t(c.size())}, self, py::dtype::of<std::int32_t>());
                             })
      .def(
          "zeros",
          [](py::object self, py::ssize_t n, const py::dtype& dt) {
            if (n < 0) throw Error("a block's size cannot be negative");
            auto bytes = static_cast<std::size_t>(n) * static_cast<std::size_t>(dt.itemsize());
            return view(self.cast<SoupBuffers&>().block(bytes), {n}, self, dt);
          },
          py::arg("n"), py::arg("dtype"), "A new block of n elements (zeros) for a channel.");
  py::class_<Job>(m, "Job")
      .def(py::init<const std::string&, const py::dict&, const py::dict&>(), py::arg("operation"), py::arg("mesh"),
           py::arg("params") = py::dict())
      .def("done", &Job::done)
      .def("wait", &Job::wait, py::arg("seconds"))
      .def("cancel", &Job::cancel)
      .def("progress", &Job::progress)
      .def("result", &Job::result);
}
