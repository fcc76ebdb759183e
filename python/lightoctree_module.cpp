// `import lightoctree`: the library's entries for Python (pybind11). Like a
// command of tools/, this only converts arguments, calls one library entry
// and converts the result; docs/python.md shows it in use.
//
// A light grid is a `Grid`: its arrays are NumPy views of the grid's own
// memory (no copy; each keeps the Grid alive), read-only so that the VDL
// sums the file contract demands cannot be broken behind its back.

#include <cxxabi.h>
#include <locale.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <clocale>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <initializer_list>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bake/bake.h"
#include "bake/convert.h"
#include "core/error.h"
#include "core/file.h"
#include "core/number_range.h"
#include "core/printable.h"
#include "core/progress.h"
#include "core/resources.h"
#include "export/lightmap_export.h"
#include "image/compare.h"
#include "image/image.h"
#include "octree/gpu_octree.h"
#include "octree/octree_irradiance.h"
#include "reference/path_tracer.h"
#include "render/context.h"
#include "render/render_session.h"
#include "scene/pinhole_camera.h"
#include "scene/scene.h"
#include "vdb/vdb_inspect.h"
#include "vdb/vdb_io.h"

// The commands' own options code (tools/, lo_tool_options): the defaults of
// `reference`, its camera choice and the scene flags, shared rather than
// retyped, so that the module and the commands cannot drift apart.
#include "camera_options.h"
#include "reference_options.h"
#include "scene_options.h"

namespace py = pybind11;

namespace lo::python {

/// An argument as Python gave it, whatever its type, checked by the function
/// that takes it and refused by its name (numberArg, wholeArg, boolArg,
/// textArg, pathArg below). pybind11's own conversion answered a wrong type
/// with "incompatible function arguments" and the whole signature, and took
/// True for 1; `T` is only the type the signature shows.
template <typename T>
struct Arg {
  py::object value;
};

}  // namespace lo::python

namespace pybind11::detail {
template <typename T>
struct type_caster<lo::python::Arg<T>> {
  PYBIND11_TYPE_CASTER(lo::python::Arg<T>, make_caster<T>::name);
  bool load(handle src, bool) {
    value.value = reinterpret_borrow<object>(src);
    return true;
  }
  static handle cast(const lo::python::Arg<T>& arg, return_value_policy, handle) {
    return arg.value.inc_ref();
  }
};
}  // namespace pybind11::detail

namespace lo::python {
namespace {

using tool::checkCameraOptions;
using tool::chooseCamera;
using tool::loadSceneWith;
using tool::ReferenceOptions;
using tool::referenceParams;
using tool::sceneInputs;
using tool::SceneOptions;

/// A grid and its metadata, shared by the arrays that view it.
struct Grid {
  VdlGrid grid;
  BakeMetadata meta;
  py::dict stats;  ///< the bake's figures (empty for a grid read from a file)
  /// The lookup's octree, built on the first lookup (a grid never changes).
  std::shared_ptr<const GpuOctree> octree;
  const GpuOctree& lookupOctree() {
    if (!octree) octree = std::make_shared<const GpuOctree>(buildGpuOctree(grid, GpuOctreeParams{}));
    return *octree;
  }
};
using GridPtr = std::shared_ptr<Grid>;

/// A read-only array of `shape` and byte `strides` over `data`, kept alive
/// by `owner`.
template <typename T>
py::array view(const py::object& owner, const T* data, std::vector<size_t> shape,
               std::vector<size_t> strides) {
  py::array a(py::dtype::of<T>(), shape, strides, data, owner);
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

py::array vec3s(const py::object& owner, const std::vector<Vec3>& v) {
  return view<float>(owner, &v.data()->x, {v.size(), 3}, {sizeof(Vec3), sizeof(float)});
}

/// The program's own locale on this thread while it lives: a progress
/// callback runs in it, as the program set it, not in the C locale of the
/// module's calls (CLocale, below; H11-1-4: a callback on the calling
/// thread saw C, one on a worker thread the program's).
struct ProgramLocale {
  ProgramLocale() : previous(uselocale(LC_GLOBAL_LOCALE)) {}
  ~ProgramLocale() { uselocale(previous); }
  ProgramLocale(const ProgramLocale&) = delete;
  ProgramLocale& operator=(const ProgramLocale&) = delete;
  locale_t previous;
};

/// Thrown through the library's loops by CallbackProgress to stop the work.
struct Stopped {};

/// The work's progress to a Python callable (task, done, total), called with
/// the interpreter's lock held (the work runs without it, on its threads),
/// and its cancellation. A sink stops a stage by throwing from begin() or
/// from update() with done < total (ProgressiveBake stops its stages so);
/// the exception leaves the stage (TBB hands it from its worker threads to
/// the caller) and the library call. Each report first runs the
/// interpreter's pending signal handlers (PyErr_CheckSignals; on the main
/// thread, which takes part in the work): Ctrl-C's KeyboardInterrupt, or an
/// exception the callback raises, stops the work at that report, and the
/// call raises it. Never thrown from end() or update(total, total), which
/// Progress's destructor sends, also while the stack unwinds.
/// The interpreter is ending (Py_Finalize has begun): a thread that takes
/// its lock now is ended there by a forced unwind (pthread_exit), which the
/// work's frames that catch everything (TBB hands exceptions between its
/// threads) swallowed: "FATAL: exception not rethrown", an abort, a crash
/// or a hang at exit when a daemon thread was inside a call (H12-1-71).
/// Set by the module's atexit hook (stopCallsAtExit): the main thread has
/// ended and the interpreter is about to.
std::atomic<bool> interpreterExiting{false};

bool interpreterEnding() {
#if PY_VERSION_HEX >= 0x030D0000
  return interpreterExiting.load() || Py_IsFinalizing() != 0;
#else
  return interpreterExiting.load() || _Py_IsFinalizing() != 0;
#endif
}

/// Calls whose work runs now without the interpreter's lock (withProgress).
std::atomic<int> callsAtWork{0};

/// The atexit hook: calls still at work (a daemon thread's) stop at their
/// next report, and the interpreter waits for them (a few seconds at most)
/// before it ends: work that ran on while the process's static objects were
/// destroyed ended it ("pure virtual method called", H12-1-71).
void stopCallsAtExit() {
  interpreterExiting = true;
  py::gil_scoped_release unlocked;  // a report waiting for the lock gets it, and stops
  for (int i = 0; i < 1000 && callsAtWork.load() > 0; ++i) ::usleep(10000);
}

/// The process that imported the module. A child forked from it hung at
/// its exit (H16-1-2): log4cplus, OpenVDB's logger, waits at exit for its
/// thread pool's threads, which the fork did not copy. Registered at import,
/// after log4cplus's own exit-time handler (the last registered runs first),
/// endForkedChild ends such a child's exit as os._exit would: after the
/// interpreter has finalised and stdio is flushed, without the libraries'
/// exit-time handlers.
pid_t importingProcess = 0;

void endForkedChild(int status, void*) {
  if (::getpid() == importingProcess) return;
  std::fflush(nullptr);
  ::_exit(status);
}

/// Where a call's thread goes when the interpreter ends under it: it waits
/// for the process to end, as Python 3.14 makes such threads wait, never
/// taking the lock (nor unwinding through frames that would need it).
[[noreturn]] void waitForTheEnd() {
  for (;;) ::pause();
}

class CallbackProgress : public ProgressSink {
 public:
  explicit CallbackProgress(py::object callback) : callback_(std::move(callback)) {}
  void begin(const std::string& task, size_t total) override { report(0, total, true, &task); }
  void update(size_t done, size_t total) override { report(done, total, done < total); }
  void end() override {}
  /// From MemoryWatch's thread (no lock): the process grew to `rss` bytes,
  /// past the limit; the next report that may stop the work stops it.
  void stopForMemory(size_t rss) {
    memoryRss_ = rss;
    stopped_ = true;
  }
  /// With the interpreter's lock: raises what stopped the work, if anything:
  /// a callback's exception or Ctrl-C's KeyboardInterrupt (also one raised at
  /// a stage's last report, after which the work ended), or, when the work
  /// did not end, MemoryError naming `call` and LIGHTOCTREE_MEMORY_LIMIT.
  void raiseIfStopped(const char* call, size_t limit, bool workEnded) {
    if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
    const size_t rss = memoryRss_.exchange(0);
    if (rss && !workEnded) {
      const char* setting = std::getenv("LIGHTOCTREE_MEMORY_LIMIT");
      const std::string text =
          std::string(call) + ": out of memory: the process grew to " + formatBytes(rss) +
          ", past LIGHTOCTREE_MEMORY_LIMIT=" + (setting ? setting : "") + " (" +
          formatBytes(limit) + "); stopped, nothing returned or written";
      PyErr_SetString(PyExc_MemoryError, text.c_str());
      throw py::error_already_set();
    }
  }

 private:
  void report(size_t done, size_t total, bool mayStop, const std::string* task = nullptr) {
    // The interpreter is ending: the work stops without its lock.
    if (!stopped_ && interpreterEnding()) stopped_ = true;
    if (!stopped_) {
      py::gil_scoped_acquire lock;
      if (task) task_ = *task;  // read by other threads' reports, under the same lock
      try {
        if (PyErr_CheckSignals() != 0) throw py::error_already_set();
        if (!callback_.is_none()) {
          const ProgramLocale programs;
          callback_(task_, done, total);
        }
      } catch (py::error_already_set&) {
        if (!stopped_.exchange(true)) error_ = std::current_exception();
      }
    }
    if (stopped_ && mayStop) throw Stopped{};
  }
  py::object callback_;
  std::string task_;
  std::atomic<bool> stopped_{false};
  std::atomic<size_t> memoryRss_{0};
  std::exception_ptr error_;
};

/// work(sink) of the Python function `call` without the interpreter's lock,
/// its progress to `progress` (a callable or None); raises what stopped it
/// (module comment above). With LIGHTOCTREE_MEMORY_LIMIT set, the process's
/// resident memory is watched as the command watches it (MemoryWatch,
/// tools/lightoctree.cpp): a call that grows past it is stopped at its next
/// progress report and raises MemoryError; the interpreter goes on, where
/// the command ends. Work that ended before a report could stop it returns.
std::string pythonNames(const std::string& message);

template <typename Work>
auto withProgress(const py::object& progress, const char* call, Work work) {
  const size_t limit = memoryLimitSetting();
  CallbackProgress sink(progress);
  std::optional<decltype(work(&sink))> result;
  std::exception_ptr failure;
  {
    // Declared after `sink`, so its thread ends before the sink goes.
    const MemoryWatch watch(limit, [&sink](size_t rss) { sink.stopForMemory(rss); });
    py::gil_scoped_release unlocked;
    ++callsAtWork;
    try {
      result.emplace(work(&sink));
    } catch (const Stopped&) {
    } catch (abi::__forced_unwind&) {
      --callsAtWork;
      throw;  // a thread ended by the system unwinds on
    } catch (...) {
      failure = std::current_exception();
    }
    --callsAtWork;
    // Taking the lock back now would end this thread by a forced unwind.
    if (interpreterEnding()) waitForTheEnd();
  }
  if (failure) {
    try {
      std::rethrow_exception(failure);
    } catch (const InputError& e) {
      // The library's advice names the command's flags ("needs --scene").
      throw InputError(pythonNames(e.what()));
    } catch (const std::bad_alloc&) {
      // Named, as the command names it: a bare MemoryError('std::bad_alloc')
      // said neither the call nor the limits (H16-1-5).
      const std::string text =
          std::string(call) +
          ": out of memory (an allocation failed): the machine or the process's limits "
          "(ulimit -v, the container's, LIGHTOCTREE_MEMORY_LIMIT) hold less than this call "
          "needs; nothing returned or written";
      PyErr_SetString(PyExc_MemoryError, text.c_str());
      throw py::error_already_set();
    }
  }
  sink.raiseIfStopped(call, limit, result.has_value());
  if (!result) throw InputError("stopped");  // not reached: a stop has its error
  return std::move(*result);
}

/// Calls that draw with OpenGL on this thread now (render; lightmap with
/// atlas_on a GL backend): one more, from their progress callback, took the
/// thread's current context and left none, and the outer call failed
/// naming a texture limit of 0 (H14-1-3). Refused by name instead.
thread_local int glCallsOnThisThread = 0;

class GlCall {
 public:
  explicit GlCall(const char* call) {
    if (glCallsOnThisThread > 0) {
      throw InputError(std::string(call) +
                       ": called from the progress callback of a call that draws with OpenGL "
                       "on this thread, whose GL context it would take: call it after that call "
                       "returns, or from another thread");
    }
    ++glCallsOnThisThread;
  }
  ~GlCall() { --glCallsOnThisThread; }
  GlCall(const GlCall&) = delete;
  GlCall& operator=(const GlCall&) = delete;
};

/// A message of the commands' options code (tools/) with its flags named as
/// the Python arguments are: "--eye and --target" -> "eye and target",
/// "--sky-image: ..." -> "sky_image: ...". A command quoted whole ("`convert
/// --photon-map`") is one to run, whose flags the module's functions may
/// not take (H17-1-2: "`convert photon_map`"): kept as it is, named as the
/// program's ("`lightoctree convert --photon-map`").
std::string pythonNames(const std::string& message) {
  static const char* const kCommands[] = {"bake",      "render",  "lightmap", "convert", "inspect",
                                          "reference", "compare", "sweep",    "view"};
  std::string out;
  for (size_t i = 0; i < message.size(); ++i) {
    const size_t close = message[i] == '`' ? message.find('`', i + 1) : std::string::npos;
    if (close != std::string::npos) {
      const std::string quoted = message.substr(i + 1, close - i - 1);
      bool command = false;
      for (const char* c : kCommands) {
        command = command || quoted.rfind(std::string(c) + " -", 0) == 0;
      }
      if (command) {
        out += "`lightoctree " + quoted + "`";
        i = close;
        continue;
      }
    }
    if (message.compare(i, 2, "--") == 0 && i + 2 < message.size() &&
        std::islower(static_cast<unsigned char>(message[i + 2])) &&
        (i == 0 || !std::isalnum(static_cast<unsigned char>(message[i - 1])))) {
      size_t j = i + 2;
      for (; j < message.size() && (std::isalnum(static_cast<unsigned char>(message[j])) ||
                                    message[j] == '-');
           ++j) {
        out += message[j] == '-' ? '_' : message[j];
      }
      i = j - 1;
    } else {
      out += message[i];
    }
  }
  return out;
}

/// Numbers in the library's text (the flags' "x,y,z", messages, metadata)
/// are written and read in the C locale, whatever locale the program that
/// imports the module set: after Python's locale.setlocale(LC_ALL,
/// "de_DE.UTF-8"), printf writes 0.5 as "0,5" and strtod stops at ".". Each
/// call of the module runs with the C locale on its thread (uselocale) and
/// gives the thread its own back after.
class CLocale {
 public:
  CLocale() : previous_(uselocale(c())) {}
  ~CLocale() { uselocale(previous_); }
  CLocale(const CLocale&) = delete;
  CLocale& operator=(const CLocale&) = delete;

 private:
  static locale_t c() {
    static const locale_t locale = newlocale(LC_ALL_MASK, "C", locale_t(0));
    return locale;
  }
  locale_t previous_;
};

/// A function of the module run under CLocale.
template <typename R, typename... A>
auto inCLocale(R (*f)(A...)) {
  return [f](A... a) -> R {
    CLocale numbers;
    return f(std::forward<A>(a)...);
  };
}

/// `work()` with an InputError of the options code reworded by pythonNames.
template <typename Work>
auto withPythonNames(Work work) {
  try {
    return work();
  } catch (const InputError& e) {
    throw InputError(pythonNames(e.what()));
  }
}

/// `text` (a message that may quote a file name or a file's metadata) as
/// UTF-8 Python decodes: bytes that are not UTF-8 shown as \xNN. Python's
/// PyErr_SetString and PyErr_WarnEx decode strictly, and answered a message
/// naming a non-UTF-8 path with a UnicodeDecodeError instead of it.
std::string validUtf8(const std::string& text) {
  py::object decoded = py::reinterpret_steal<py::object>(
      PyUnicode_DecodeUTF8(text.data(), py::ssize_t(text.size()), "backslashreplace"));
  if (!decoded) throw py::error_already_set();
  return decoded.cast<std::string>();
}

/// The commands' "warning: ..." on stderr, as Python's warnings.warn(text)
/// (a UserWarning, shown once per place by default, or raised where the
/// caller made warnings errors); nothing for "".
void warn(const std::string& text) {
  if (text.empty()) return;
  if (PyErr_WarnEx(PyExc_UserWarning, validUtf8(text).c_str(), 1) != 0) {
    throw py::error_already_set();
  }
}

/// Each of `warnings` (a loaded scene's, a render session's) through warn(),
/// as the commands print them.
void warnEach(const std::vector<std::string>& warnings) {
  for (const std::string& w : warnings) warn(w);
}

// ---- arguments: each checked by its name, as the commands check their flags ----

/// repr(value), cut to 60 characters (a refused argument may be large).
std::string shortRepr(const py::handle& value) {
  try {
    std::string r = py::repr(value);
    return r.size() > 60 ? r.substr(0, 57) + "..." : r;
  } catch (const py::error_already_set&) {
    return "a " + std::string(py::str(py::type::of(value).attr("__name__")));
  }
}

/// True and False, NumPy's included: never a number here.
bool isBool(const py::handle& value) {
  if (PyBool_Check(value.ptr())) return true;
  const py::handle type = py::type::of(value);
  const std::string name = py::str(type.attr("__name__"));
  return (name == "bool_" || name == "bool") &&
         std::string(py::str(type.attr("__module__"))) == "numpy";
}

[[noreturn]] void refuse(const std::string& name, const std::string& what,
                         const py::handle& value) {
  throw InputError(name + ": must be " + what + ", got " + shortRepr(value));
}

/// numbers.Real, looked up when the module is imported. Not a function's
/// static: its first use, an import, may let another thread take the lock,
/// which then waited on the static's guard holding the lock: two threads'
/// first calls hung for ever (H12-1-71's runs). A handle, never released:
/// nothing to free while the interpreter ends.
py::handle realNumberType;

/// The number `value` holds (int, float, a NumPy number; not a bool, not a
/// string), else nullopt.
std::optional<double> numberOf(const py::handle& value) {
  // A real number: not a complex one (NumPy's gave its real part with only a
  // warning, H12-1-59), nor an object that merely converts to float.
  if (isBool(value) || !(PyFloat_Check(value.ptr()) || PyLong_Check(value.ptr()) ||
                         py::isinstance(value, realNumberType))) {
    return std::nullopt;
  }
  const double v = PyFloat_AsDouble(value.ptr());  // int beyond a double: OverflowError
  if (v == -1.0 && PyErr_Occurred()) {
    // Not a number: refused by name. Ctrl-C, MemoryError or another error
    // raised by the object's own __float__ goes on as itself (H16-1-1).
    if (!PyErr_ExceptionMatches(PyExc_TypeError) && !PyErr_ExceptionMatches(PyExc_ValueError) &&
        !PyErr_ExceptionMatches(PyExc_OverflowError)) {
      throw py::error_already_set();
    }
    PyErr_Clear();
    return std::nullopt;
  }
  return v;
}

/// The one check of a number argument: a number within `range` (the range of
/// the command's flag, core/number_range.h), else InputError naming it:
/// "tolerance: must be a finite number from 0 to 1, got '0.1'".
double numberArg(const py::handle& value, const NumberRange& range, const std::string& name) {
  const std::optional<double> v = numberOf(value);
  if (!v || !range.contains(*v)) refuse(name, range.ToString(), value);
  return *v;
}

/// numberArg for a setting whose 0 means "not given" (`unset` says what 0 is).
double numberOrZeroArg(const py::handle& value, const NumberRange& range, const std::string& name,
                       const std::string& unset) {
  const std::optional<double> v = numberOf(value);
  if (v && *v == 0) return 0;
  if (!v || !range.contains(*v)) refuse(name, "0 (" + unset + ") or " + range.ToString(), value);
  return *v;
}

/// A whole number from `min` to `max` (4.0 taken, as the flags take "4.0";
/// 4.5, NaN and True refused).
int wholeArg(const py::handle& value, double min, double max, const std::string& name) {
  return int(numberArg(value, NumberRange{min, max, false, true}, name));
}

/// A seed: a whole number from 0 to 2^64 - 1, exactly (as --seed).
uint64_t seedArg(const py::handle& value, const std::string& name) {
  const char* what = "a whole number from 0 to 18446744073709551615";
  if (isBool(value) || !PyIndex_Check(value.ptr())) refuse(name, what, value);
  const py::int_ seed = py::reinterpret_steal<py::int_>(PyNumber_Index(value.ptr()));
  if (!seed) throw py::error_already_set();
  if (seed < py::int_(0) || seed > py::int_(std::numeric_limits<uint64_t>::max())) {
    refuse(name, what, value);
  }
  return seed.cast<uint64_t>();
}

/// `value` when it is one of `choices`. @throws InputError naming `name`.
const std::string& checkChoice(const std::string& value, std::initializer_list<const char*> choices,
                               const std::string& name) {
  std::string list;
  for (const char* c : choices) {
    if (value == c) return value;
    list += std::string(list.empty() ? "'" : ", '") + c + "'";
  }
  throw InputError(name + ": must be one of " + list + ", got '" + value + "'");
}

bool boolArg(const py::handle& value, const std::string& name) {
  if (!isBool(value)) refuse(name, "True or False", value);
  return PyObject_IsTrue(value.ptr()) == 1;
}

std::string textArg(const py::handle& value, const std::string& name) {
  if (!py::isinstance<py::str>(value)) refuse(name, "a string", value);
  // Text UTF-8 can hold: a lone surrogate ('\udcff') failed pybind11's cast
  // with its bare "Unable to cast" (H13-1-63).
  py::ssize_t size = 0;
  const char* utf8 = PyUnicode_AsUTF8AndSize(value.ptr(), &size);
  if (!utf8) {
    PyErr_Clear();
    refuse(name, "a string of text (this one holds a lone surrogate)", value);
  }
  const std::string text(utf8, size_t(size));
  // A NUL cut the messages that quote it (H12-1-66).
  if (text.find('\0') != std::string::npos) refuse(name, "a string without NUL bytes", value);
  return text;
}

/// A number of VDLs as --vdls takes it: 1 to kMaxVdls or "auto", as a
/// number or as text ("" where `empty` says what it means).
std::string vdlsArg(const py::handle& value, const std::string& name, const char* empty = nullptr) {
  std::string text;
  if (py::isinstance<py::int_>(value) && !isBool(value)) {
    text = py::str(value);
  } else if (py::isinstance<py::str>(value)) {
    text = textArg(value, name);
  } else {
    text = "?";  // refused below
  }
  if (empty && text.empty()) return text;
  if (!vdlCountError(text).empty()) {
    const std::string none = empty ? "'' (" + std::string(empty) + "), " : "";
    refuse(name, none + "a whole number from 1 to " + std::to_string(kMaxVdls) + " or 'auto'",
           value);
  }
  return text;
}

/// A path argument: str, bytes or os.PathLike, as Python's own open() takes
/// them: the bytes os.fsencode gives, which are the file's name whatever its
/// encoding (a name that is not UTF-8 comes as bytes, or as a str of
/// os.fsdecode with its bytes as surrogate escapes; pybind11's str to UTF-8
/// raised UnicodeEncodeError on those, bytes were refused, and a PathLike of
/// bytes was taken as the text "b'...'"). Checked as checkPathText.
std::string pathArg(const py::handle& value, const std::string& name, bool mayBeEmpty = false) {
  if (!py::isinstance<py::str>(value) && !py::isinstance<py::bytes>(value) &&
      !py::hasattr(value, "__fspath__")) {
    refuse(name, "a path (str, bytes or os.PathLike)", value);
  }
  py::object encoded;
  try {
    encoded = py::module_::import("os").attr("fsencode")(value);
  } catch (py::error_already_set& e) {
    // A str with a surrogate that is not an escaped byte, an __fspath__
    // that returns neither str nor bytes.
    throw InputError(name + ": " + std::string(py::repr(value)) +
                     " is not a file name the system can take (" + e.what() + ")");
  }
  const std::string path = encoded.cast<std::string>();
  // '' named no file: "InputError: : file does not exist".
  if (path.empty() && !mayBeEmpty) throw InputError(name + ": the path is empty: name a file");
  checkPathText(path, name);
  return path;
}

/// A grid argument: a lightoctree.Grid (from bake, read or convert); pybind11's
/// own conversion answered None with "incompatible function arguments",
/// naming no argument.
Grid& gridArg(const py::handle& value, const std::string& name) {
  if (!py::isinstance<Grid>(value)) {
    refuse(name, "a lightoctree.Grid (from bake, read or convert)", value);
  }
  return value.cast<Grid&>();
}

/// `value` as an array of T (NumPy converts lists, tuples and other numeric
/// arrays), or null where it holds no real numbers: bools (taken as 1 and
/// 0), complex numbers (their imaginary part dropped with only a NumPy
/// warning), text, or objects NumPy cannot convert (its bare ValueError
/// named no argument; H11-1-28/29, H10-1-73).
/// With `bools`, bools are taken as 1 and 0 (a mask). An array of objects is
/// taken when each is a real number (strings of digits were read as numbers,
/// H12-1-34). `dtype` gets what NumPy saw, for the refusal.
template <typename T>
std::optional<py::array_t<T, py::array::c_style | py::array::forcecast>> realArray(
    const py::handle& value, std::string& dtype, bool bools = false) {
  using Array = py::array_t<T, py::array::c_style | py::array::forcecast>;
  if (value.is_none() || py::isinstance<py::str>(value) || py::isinstance<py::bytes>(value)) {
    return std::nullopt;
  }
  try {
    const py::object seen = py::module_::import("numpy").attr("asarray")(value);
    dtype = py::str(seen.attr("dtype"));
    const char kind = py::str(seen.attr("dtype").attr("kind")).cast<std::string>().at(0);
    if (kind == 'O') {
      for (const py::handle item : seen.attr("flat")) {
        if (!numberOf(item)) return std::nullopt;
      }
    } else if (kind != 'i' && kind != 'u' && kind != 'f' && !(bools && kind == 'b')) {
      return std::nullopt;
    }
    Array a = Array::ensure(seen);
    // ensure() clears what stopped it: a Ctrl-C then was taken for a bad
    // argument (H14-1-1), and is raised.
    if (!a && PyErr_CheckSignals() != 0) throw py::error_already_set();
    if (!a) return std::nullopt;
    return a;
  } catch (const py::error_already_set& e) {
    // Ctrl-C (KeyboardInterrupt), MemoryError: not the argument's fault.
    if (!e.matches(PyExc_TypeError) && !e.matches(PyExc_ValueError) &&
        !e.matches(PyExc_OverflowError)) {
      throw;
    }
    return std::nullopt;
  }
}

/// An (N, 3) array of numbers as doubles, refused by its name when it holds
/// anything else.
py::array_t<double, py::array::c_style | py::array::forcecast> pointsArg(const py::handle& value,
                                                                           const std::string& name) {
  std::string dtype;
  const auto a = realArray<double>(value, dtype);
  if (!a || a->ndim() != 2 || a->shape(1) != 3) {
    refuse(name, "an array of numbers of shape (N, 3)", value);
  }
  return *a;
}

/// A path for Python, as os.fsdecode gives it: a str whatever the bytes, which
/// open() and pathArg take back to the same bytes.
py::object pathValue(const std::string& path) {
  return py::module_::import("os").attr("fsdecode")(py::bytes(path));
}

GridPtr readGrid(const Arg<std::string>& pathArgument) {
  const std::string path = pathArg(pathArgument.value, "path");
  // Without the interpreter's lock, as the other long calls (a depth-8 grid
  // reads for seconds; other threads stood still, H16-1-4).
  LoadedVdl loaded =
      withProgress(py::none(), "read", [&](ProgressSink*) { return readVdlGrid(path); });
  auto out = std::make_shared<Grid>();
  out->grid = std::move(loaded.grid);
  out->meta = std::move(loaded.meta);
  return out;
}

py::dict inspectFile(const Arg<std::string>& pathArgument) {
  const std::string path = pathArg(pathArgument.value, "path");
  const VdbReport r =
      withProgress(py::none(), "inspect", [&](ProgressSink*) { return inspectVdb(path); });
  py::dict d;
  d["path"] = pathValue(r.path);
  d["kind"] = r.kind;
  d["bytes"] = r.fileBytes;
  d["ok"] = r.ok();
  py::list checks;
  for (const VdbCheck& c : r.checks) {
    py::dict check;
    check["name"] = c.name;
    check["passed"] = c.passed;
    check["detail"] = validUtf8(c.detail);
    checks.append(check);
  }
  d["checks"] = checks;
  py::dict meta;
  // Another tool's metadata need not be UTF-8 (as the CLI's JSON report).
  for (const auto& [key, value] : r.metadata) meta[py::str(validUtf8(key))] = validUtf8(value);
  d["metadata"] = meta;
  return d;
}

GridPtr convertGrid(const Arg<Grid>& gridValue, const Arg<int>& depthArg,
                    const Arg<std::string>& vdlsValue, const Arg<std::string>& sceneArg) {
  const Grid& in = gridArg(gridValue.value, "grid");
  const int depth = int(numberOrZeroArg(depthArg.value, kDepthRange, "depth", "the grid's own"));
  const std::string vdls = vdlsArg(vdlsValue.value, "vdls", "the grid's own");
  const std::string scenePath = pathArg(sceneArg.value, "scene", true);  // '': none
  ConvertParams params;
  params.depth = depth;
  params.vdls = vdls;
  Scene scene;
  if (!scenePath.empty()) {
    scene = loadScene(scenePath);
    warnEach(scene.warnings);
    params.scene = &scene;
  }
  // No callback (convert takes none), but Ctrl-C and the memory watch stop it.
  ConvertResult r = withProgress(py::none(), "convert", [&](ProgressSink* sink) {
    return convertLightGrid(in.grid, in.meta, params, sink);
  });
  auto out = std::make_shared<Grid>();
  out->grid = std::move(r.grid);
  out->meta = std::move(r.metadata);
  return out;
}

/// Row `i` of an (N, 3) array as "(x, y, z)", for a refusal.
std::string rowText(const double* v, size_t i) {
  char text[96];
  std::snprintf(text, sizeof text, "(%.9g, %.9g, %.9g)", v[3 * i], v[3 * i + 1], v[3 * i + 2]);
  return text;
}

/// E(p, n) through the CPU copy of the renderer's octree lookup. A point or
/// normal that is not finite is refused by its argument and row, as every
/// other argument of the module is by its name: the lookup has no answer
/// there (it gave 0, a value a caller cannot tell from darkness), and NaN in
/// the result would spread silently through the caller's sums.
py::array_t<float> lookup(const Arg<Grid>& gridValue, const Arg<py::array_t<double>>& pointsValue,
                          const Arg<py::array_t<double>>& normalsValue) {
  Grid& g = gridArg(gridValue.value, "grid");
  const auto points = pointsArg(pointsValue.value, "points");
  const auto normals = pointsArg(normalsValue.value, "normals");
  if (normals.shape(0) != points.shape(0)) {
    throw InputError("normals: " + std::to_string(normals.shape(0)) + " rows, where points has " +
                     std::to_string(points.shape(0)) + ": one normal per point");
  }
  const size_t n = size_t(points.shape(0));
  const double* p = points.data();
  const double* nn = normals.data();
  // Checked as the lookup takes them, in single precision: 1e39 is inf there.
  auto vec = [](const double* v, size_t i) {
    return Vec3(float(v[3 * i]), float(v[3 * i + 1]), float(v[3 * i + 2]));
  };
  for (size_t i = 0; i < n; ++i) {
    if (!isFinite(vec(p, i))) {
      throw InputError("points: row " + std::to_string(i) + " is " + rowText(p, i) +
                       ": every point must be finite (within a float's range)");
    }
    const Vec3 normal = vec(nn, i);
    if (!isFinite(normal) || (normal.x == 0 && normal.y == 0 && normal.z == 0)) {
      throw InputError("normals: row " + std::to_string(i) + " is " + rowText(nn, i) +
                       ": every normal must be a finite direction of non-zero length");
    }
  }
  const GpuOctree& octree = g.lookupOctree();
  py::array_t<float> out({n, size_t(3)});
  float* e = out.mutable_data();
  // In chunks of about a tenth of a second, Ctrl-C heard between them: 10^7
  // points took 14 s, deaf (H14-1-2).
  constexpr size_t kChunk = size_t(1) << 16;
  for (size_t start = 0; start < n; start += kChunk) {
    {
      py::gil_scoped_release unlocked;
      for (size_t i = start; i < std::min(n, start + kChunk); ++i) {
        const Vec3 v = octreeIrradiance(octree, vec(p, i), normalize(vec(nn, i)));
        e[3 * i] = v.x;
        e[3 * i + 1] = v.y;
        e[3 * i + 2] = v.z;
      }
      if (interpreterEnding()) waitForTheEnd();
    }
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  }
  return out;
}

/// The render settings the keywords select: the command line's flags by
/// their Python names, defaults the library's (RenderSettings{}), so that
/// `lightoctree.render` draws what `lightoctree render` draws.
/// A keyword `progress`: a callable (task, done, total) or None.
py::object progressArg(const py::handle& value, const std::string& name) {
  if (!value.is_none() && !PyCallable_Check(value.ptr())) {
    refuse(name, "a callable (task, done, total) or None", value);
  }
  return py::reinterpret_borrow<py::object>(value);
}

RenderSettings renderSettings(const Arg<int>& width, const Arg<int>& height,
                              const Arg<std::string>& mode, const py::kwargs& kw) {
  // The ranges and words of the command's flags (tools/render_options.cpp).
  RenderSettings s;
  s.frame.width = wholeArg(width.value, 1, kMaxImageSide, "width");
  s.frame.height = wholeArg(height.value, 1, kMaxImageSide, "height");
  s.frame.mode = parseRenderMode(
      checkChoice(textArg(mode.value, "mode"), {"full", "direct", "indirect", "voxels"}, "mode"));
  for (const auto& [key, value] : kw) {
    const std::string name = py::str(key);
    if (name == "interpolation") {
      s.frame.interpolation = boolArg(value, name);
    } else if (name == "specular") {
      s.frame.specular = boolArg(value, name);
    } else if (name == "reflections") {
      s.frame.reflections = boolArg(value, name);
    } else if (name == "lighting") {
      const std::string lighting = checkChoice(textArg(value, name), {"octree", "atlas"}, name);
      s.frame.lighting = parseLighting(lighting);
    } else if (name == "supersample") {
      s.frame.supersample = wholeArg(value, 1, kMaxSupersample, name);
    } else if (name == "vdls") {
      s.frame.maxVdls = wholeArg(value, 1, kMaxVdls, name);
    } else if (name == "area_lights") {
      s.renderer.areaLights = boolArg(value, name);
    } else if (name == "emitter_lights") {
      s.renderer.emitterLights = wholeArg(value, 0, kMaxEmitterLights, name);
    } else if (name == "shadow_map_size") {
      s.renderer.shadowMapSize = wholeArg(value, kMinShadowMapSize, kMaxShadowMapSize, name);
    } else if (name == "cosine_correction") {
      s.octree.cosineCorrection = boolArg(value, name);
    } else if (name == "tolerance") {
      s.octree.tolerance = float(numberArg(value, {0, 1}, name));
    } else if (name == "free_space_tolerance") {
      s.octree.volumeTolerance = float(numberArg(value, {0, 1}, name));
    } else if (name == "texels") {
      setTexels(s.octree, checkChoice(textArg(value, name), {"float", "half", "compact"}, name));
    } else if (name == "progress") {
      progressArg(value, name);  // the call's (renderImage), not the picture's
    } else {
      throw InputError("render: unknown setting '" + printable(name) + "'");
    }
  }
  s.check();
  return s;
}

/// The scene lit by the grid, drawn by the GL renderer (OSMesa, headless)
/// from the scene's camera through the library's render session: linear
/// RGB, shape (height, width, 3).
py::array_t<float> renderImage(const Arg<std::string>& sceneArg, const Arg<Grid>& gridValue,
                               const Arg<int>& width, const Arg<int>& height,
                               const Arg<std::string>& mode, const py::kwargs& kw) {
  const std::string scenePath = pathArg(sceneArg.value, "scene");
  const Grid& g = gridArg(gridValue.value, "grid");
  // Its checks (the frame's memory among them) name the flags.
  const RenderSettings settings =
      withPythonNames([&] { return renderSettings(width, height, mode, kw); });
  Scene scene = loadScene(scenePath);
  warnEach(scene.warnings);
  // Before the frame, as `render` warns.
  for (const std::string& w : gridWarnings(g.meta, scene)) warn("grid: " + w);
  const RenderMode drawn = settings.frame.mode;
  if (drawn == RenderMode::Full || drawn == RenderMode::Direct) {
    const std::string twice =
        directTwiceWarning(g.meta, "mode '" + toString(drawn) + "'", "use mode='indirect'");
    if (!twice.empty()) warn("grid: " + pythonNames(twice));
  }
  RgbImage image;
  std::vector<std::string> sessionWarnings;  // said once the work is done (the lock held)
  // The renderer's refusals name the flags ("--emitter-lights"); Ctrl-C
  // stops it between its set-up's stages and between frames.
  const GlCall drawing("render");
  withPythonNames([&] {
    const py::object progress = kw.contains("progress") ? progressArg(kw["progress"], "progress")
                                                        : py::object(py::none());
    return withProgress(progress, "render", [&](ProgressSink* sink) {
      GlContextParams contextParams;
      contextParams.backend = GlBackend::OSMesa;
      std::unique_ptr<GlContext> context = createGlContext(contextParams);
      RenderSessionOptions options;
      options.progress = sink;
      RenderSession session(scene, g.grid, *context, settings, options);
      sessionWarnings = session.warnings();
      // The scene's first camera, else one framing its bounds from the side
      // its surfaces face (as `render`).
      image = session.render(PinholeCamera::ofScene(scene), settings.frame.mode);
      return 0;
    });
  });
  warnEach(sessionWarnings);
  py::array_t<float> out({size_t(settings.frame.height), size_t(settings.frame.width), size_t(3)});
  std::copy(image.rgb.begin(), image.rgb.end(), out.mutable_data());
  return out;
}

/// An EXR (linear) or PNG (sRGB decoded) image as (height, width, 3) floats.
py::array_t<float> readImageFile(const Arg<std::string>& pathArgument) {
  const std::string path = pathArg(pathArgument.value, "path");
  // Without the lock (a large PNG decodes for seconds), and the array holds
  // the image's floats rather than a copy of them.
  auto image = std::make_unique<RgbImage>(
      withProgress(py::none(), "read_image", [&](ProgressSink*) { return readImage(path); }));
  const std::array<size_t, 3> shape = {size_t(image->height), size_t(image->width), 3};
  float* data = image->rgb.data();
  py::capsule owner(image.get(), [](void* held) { delete static_cast<RgbImage*>(held); });
  image.release();
  return py::array_t<float>(shape, data, owner);
}

// ---- reference, compare, lightmap: the commands' settings and defaults ----

/// Three numbers, or their text "x,y,z", as the flags' text "x,y,z" that
/// parseVec3d reads (%.17g gives every double back exactly).
std::string vec3Text(const py::handle& value, const std::string& name) {
  if (py::isinstance<py::str>(value)) return textArg(value, name);
  // Three real numbers each (True or a complex number was read as 1 or its
  // real part, H12-1-35).
  std::vector<double> v;
  // bytes are a sequence of small numbers: b'abc' was taken as (97, 98, 99).
  const bool bytes = py::isinstance<py::bytes>(value) || py::isinstance<py::bytearray>(value);
  if (!bytes && py::isinstance<py::sequence>(value) && py::len(value) == 3) {
    for (const py::handle item : value) {
      const std::optional<double> x = numberOf(item);
      if (!x) break;
      v.push_back(*x);
    }
  }
  if (v.size() != 3) {
    throw InputError(name + ": expected three numbers x, y, z, got " + shortRepr(value));
  }
  char text[96];
  std::snprintf(text, sizeof text, "%.17g,%.17g,%.17g", v[0], v[1], v[2]);
  return text;
}

/// The scene flags every command shares (tools/scene_options.h): sky,
/// sky_image, sky_mesh, physical_sky; None = not given.
SceneOptions sceneOptions(const py::object& sky, const py::object& skyImage,
                          const py::object& skyMesh, const py::object& physicalSky) {
  SceneOptions o;
  if (!sky.is_none()) o.sky = vec3Text(sky, "sky");
  if (!skyImage.is_none()) o.skyImage = pathArg(skyImage, "sky_image");
  if (!skyMesh.is_none()) o.skyMesh = textArg(skyMesh, "sky_mesh");
  if (!physicalSky.is_none()) {
    // kMinTurbidity, kMaxTurbidity, as the flag's range.
    o.physicalSky = float(numberArg(physicalSky, {1.7, 10.0}, "physical_sky"));
  }
  if (!o.skyImage.empty() && (!o.skyMesh.empty() || o.physicalSky > 0)) {
    throw InputError(std::string(o.skyMesh.empty() ? "physical_sky" : "sky_mesh") +
                     " and sky_image: give one of them");
  }
  if (!o.skyMesh.empty() && o.physicalSky > 0) {
    throw InputError("physical_sky and sky_mesh: give one of them");
  }
  return o;
}

/// `lightoctree bake`: the arguments are checked as the command's flags are,
/// by the same ranges (bake/bake.h, core/number_range.h), and named by their
/// Python names; 0 is "not given" for photons and target_error, as their
/// defaults. The sky keywords light the scene as the flags do (None: the
/// file's own sky); `lightmap` needs the same ones for the same light.
GridPtr bakeScene(const Arg<std::string>& sceneArg, const Arg<int>& depthArg,
                  const Arg<size_t>& photonsArg, const Arg<double>& targetErrorArg,
                  const Arg<uint64_t>& seedArgument, const Arg<int>& knnArg,
                  const Arg<std::string>& vdlsValue, const Arg<bool>& includeDirectArg,
                  const Arg<std::string>& targetLightArg, const py::object& progress,
                  const Arg<std::string>& representationArg, const py::object& sky,
                  const py::object& skyImage, const py::object& skyMesh,
                  const py::object& physicalSky) {
  const std::string scenePath = pathArg(sceneArg.value, "scene");
  progressArg(progress, "progress");
  // "auto" (the default) or a whole number, as --depth; a number as text is
  // refused, as for every argument.
  int depth = kAutoDepth;
  if (py::isinstance<py::str>(depthArg.value)) {
    const std::string text = textArg(depthArg.value, "depth");
    if (text != "auto") {
      throw InputError("depth: must be 'auto' or " + kDepthRange.ToString() + ", got '" +
                       printable(text) + "'");
    }
  } else {
    depth = int(numberArg(depthArg.value, kDepthRange, "depth"));
  }
  const auto photons =
      size_t(numberOrZeroArg(photonsArg.value, kPhotonsRange, "photons", "not given"));
  const double targetError =
      numberOrZeroArg(targetErrorArg.value, kTargetErrorRange, "target_error", "the default");
  const uint64_t seed = seedArg(seedArgument.value, "seed");
  const int knn = int(numberArg(knnArg.value, kKnnRange, "knn"));
  const std::string vdls = vdlsArg(vdlsValue.value, "vdls");
  const bool includeDirect = boolArg(includeDirectArg.value, "include_direct");
  const std::string targetLight = checkChoice(textArg(targetLightArg.value, "target_light"),
                                              {"seen", "indirect"}, "target_light");
  const std::string representation = textArg(representationArg.value, "representation");
  BakeParams params;
  if (!parseRepresentation(representation, &params.representation)) {
    throw InputError("representation: must be " + representationChoices() + ", got '" +
                     representation + "'");
  }
  const SceneOptions lighting = sceneOptions(sky, skyImage, skyMesh, physicalSky);
  Scene scene = withPythonNames([&] { return loadSceneWith(scenePath, lighting); });
  warnEach(scene.warnings);
  params.depth = depth;
  setPhotonBudget(params, photons, targetError);
  params.seed = seed;
  params.knn = knn;
  params.vdls = parseVdlCount(vdls, "vdls");
  params.includeDirect = includeDirect;
  params.targetSeenLight = targetLight == "seen";
  const std::string sparse = sparsePhotonsWarning(scene, params);
  if (!sparse.empty()) warn(pythonNames(sparse));
  auto out = std::make_shared<Grid>();
  BakeResult r = withProgress(progress, "bake", [&](ProgressSink* sink) {
    BakeResult result = bake(scene, params, sink);
    recordSourceScene(result.metadata, scene);
    return result;
  });
  out->grid = std::move(r.grid);
  out->meta = std::move(r.metadata);
  out->stats["stored_photons"] = r.stats.storedPhotons;
  out->stats["emitted_paths"] = r.stats.emittedPaths;
  out->stats["noise"] = r.stats.noise.ToString();
  out->stats["passes"] = r.stats.passes.size();
  return out;
}

py::array_t<float> imageArray(const RgbImage& image) {
  py::array_t<float> out({size_t(image.height), size_t(image.width), size_t(3)});
  std::copy(image.rgb.begin(), image.rgb.end(), out.mutable_data());
  return out;
}

/// `lightoctree reference`: the path tracer's picture of the scene from the
/// camera the command chooses, with the command's defaults (ReferenceOptions).
py::object referenceImage(const Arg<std::string>& sceneArg, const Arg<int>& width,
                          const Arg<int>& height, const Arg<int>& spp, const Arg<std::string>& part,
                          const Arg<uint64_t>& seed, const Arg<int>& maxBounces,
                          const py::object& camera, const py::object& eye,
                          const py::object& target, const Arg<double>& fov,
                          const Arg<double>& timeBudget, const Arg<bool>& withStdErrorArg,
                          const py::object& progress, const py::object& sky,
                          const py::object& skyImage, const py::object& skyMesh,
                          const py::object& physicalSky) {
  ReferenceOptions opt;  // the command's flags, as given
  opt.scene = pathArg(sceneArg.value, "scene");
  progressArg(progress, "progress");
  const bool withStdError = boolArg(withStdErrorArg.value, "std_error");
  // The ranges of the command's flags (tools/reference_options.cpp,
  // command_options.cpp, camera_options.cpp); python/tests check that both
  // refuse the same values.
  opt.width = wholeArg(width.value, 1, kMaxImageSide, "width");
  opt.height = wholeArg(height.value, 1, kMaxImageSide, "height");
  if (!spp.value.is_none()) opt.spp = wholeArg(spp.value, 1, 1000000, "spp");
  opt.maxBounces = wholeArg(maxBounces.value, 0, 100000, "max_bounces");
  opt.part = checkChoice(textArg(part.value, "part"), {"full", "direct", "indirect", "irradiance"},
                         "part");
  if (!seed.value.is_none()) opt.seed = seedArg(seed.value, "seed");
  if (!timeBudget.value.is_none()) {
    opt.timeBudget = numberArg(timeBudget.value, {1e-3, 1e7}, "time_budget");
    // As the command: "--spp excludes --time-budget" (spp was taken and ignored).
    if (!spp.value.is_none()) {
      throw InputError("spp and time_budget: give one of them (time_budget renders passes of 1 "
                       "sample per pixel until it runs out)");
    }
  }
  if (!camera.is_none()) {
    opt.camera.camera = textArg(camera, "camera");
    const std::string problem = tool::cameraNameProblem(opt.camera.camera);
    if (!problem.empty()) throw InputError("camera: " + problem);
  }
  if (!eye.is_none()) opt.camera.eye = vec3Text(eye, "eye");
  if (!target.is_none()) opt.camera.target = vec3Text(target, "target");
  if (!opt.camera.camera.empty() && !opt.camera.eye.empty()) {
    throw InputError("camera and eye: give one of them");
  }
  if (!fov.value.is_none()) opt.camera.fovDegrees = float(numberArg(fov.value, kFovDegreesRange, "fov"));
  opt.sceneOptions = sceneOptions(sky, skyImage, skyMesh, physicalSky);
  withPythonNames([&] {
    checkCameraOptions(opt.camera);
    checkStdErrorSamples(opt, withStdError);
    return 0;
  });
  const ReferenceParams params = referenceParams(opt);
  std::vector<std::string> sceneWarnings;  // said once the work is done (the lock held)
  const ReferenceImage r = withPythonNames([&] {
    return withProgress(progress, "reference", [&](ProgressSink* sink) {
      const Scene scene = loadSceneWith(opt);
      sceneWarnings = scene.warnings;
      const PinholeCamera view = chooseCamera(opt.camera, scene, opt.scene);
      return renderReference(scene, view, params, sink);
    });
  });
  warnEach(sceneWarnings);
  withPythonNames([&] {
    checkStdErrorSamples(opt, withStdError, r.samplesPerPixel);
    return 0;
  });
  if (std::all_of(r.image.rgb.begin(), r.image.rgb.end(), [](float v) { return v == 0; })) {
    warn(
        "every pixel is black: no light reaches what the camera sees (a scene without a light "
        "of positive power, an emissive surface or a sky?)");
  }
  py::array_t<float> image = imageArray(r.image);
  if (!withStdError) return std::move(image);
  return py::make_tuple(image, imageArray(r.stdError));
}

/// An image argument of compare: a path (EXR linear, PNG decoded; a mask's
/// 8-bit values as plain numbers, as `compare --mask`) or an array of shape
/// (height, width, 3) (a mask also (height, width)). `path` gets the path.
RgbImage imageArg(const py::object& value, const std::string& name, bool isMask,
                  std::string* path) {
  if (py::isinstance<py::str>(value) || py::isinstance<py::bytes>(value) ||
      py::hasattr(value, "__fspath__")) {
    *path = pathArg(value, name);
    return readImage(*path, isMask);
  }
  std::string dtype;
  const auto array = realArray<float>(value, dtype, isMask);  // a mask may be bools
  const bool plane = isMask && array && array->ndim() == 2;
  if (!array || !((array->ndim() == 3 && array->shape(2) == 3) || plane) ||
      array->shape(0) < 1 || array->shape(1) < 1 || array->shape(0) > kMaxImageSide ||
      array->shape(1) > kMaxImageSide) {
    // What was given: the array's shape, else the dtype NumPy saw (an array
    // of text or complex numbers), else its type.
    const std::string given =
        array ? "shape " + std::string(py::str(py::tuple(py::cast(std::vector<py::ssize_t>(
                                array->shape(), array->shape() + array->ndim())))))
        : !dtype.empty() ? "an array of dtype " + dtype
                         : std::string(py::repr(py::type::of(value)));
    throw InputError(name + ": must be a path or an array of " +
                     std::string(isMask ? "numbers or bools" : "numbers") +
                     " of shape (height, width, 3)" +
                     std::string(isMask ? " or (height, width)" : "") + " of 1 to " +
                     std::to_string(kMaxImageSide) + " pixels a side, got " + given);
  }
  const auto& a = *array;
  RgbImage image(int(a.shape(1)), int(a.shape(0)));
  const float* data = a.data();
  if (plane) {
    for (size_t i = 0; i < image.pixelCount(); ++i) image.set(i, Vec3(data[i]));
  } else {
    std::copy(data, data + image.rgb.size(), image.rgb.begin());
  }
  return image;
}

std::string sizeText(const std::string& name, const std::string& path, const RgbImage& image) {
  return name + (path.empty() ? "" : " '" + path + "'") + " is " + std::to_string(image.width) +
         " x " + std::to_string(image.height);
}

py::dict channelDict(const ChannelError& e) {
  py::dict d;
  d["rel_rmse"] = e.relRmse;
  d["rel_mae"] = e.relMae;
  d["max_abs"] = e.maxAbs;
  return d;
}

/// `lightoctree compare`: compareReport's figures as `compare --json` writes them.
py::dict compareImagesArg(const py::object& testArg, const py::object& referenceArg,
                          const Arg<int>& bin, const Arg<double>& clipPercentile,
                          const py::object& maskArg, const Arg<bool>& ignoreBackground,
                          const py::object& referenceErrorArg) {
  CompareSettings settings;
  settings.bin = int(numberArg(bin.value, kCompareBinRange, "bin"));
  settings.clipPercentile =
      float(numberArg(clipPercentile.value, kClipPercentileRange, "clip_percentile"));
  settings.ignoreBackground = boolArg(ignoreBackground.value, "ignore_background");
  std::string testPath, referencePath, maskPath, errorPath;
  const RgbImage test = imageArg(testArg, "test", false, &testPath);
  const RgbImage reference = imageArg(referenceArg, "reference", false, &referencePath);
  if (test.width != reference.width || test.height != reference.height) {
    throw InputError(sizeText("test", testPath, test) + " but " +
                     sizeText("reference", referencePath, reference));
  }
  std::optional<RgbImage> mask, stdError;
  if (!maskArg.is_none()) mask = imageArg(maskArg, "mask", true, &maskPath);
  if (!referenceErrorArg.is_none()) {
    stdError = imageArg(referenceErrorArg, "reference_error", false, &errorPath);
    checkStdError(*stdError, errorPath.empty() ? "reference_error"
                                               : "reference_error: " + printable(errorPath));
  }
  if (mask && (mask->width != reference.width || mask->height != reference.height)) {
    throw InputError("mask: " + sizeText("the mask", maskPath, *mask) + ", the images are " +
                     std::to_string(reference.width) + " x " + std::to_string(reference.height));
  }
  if (stdError && (stdError->width != reference.width || stdError->height != reference.height)) {
    throw InputError("reference_error: " + sizeText("the standard error", errorPath, *stdError) +
                     ", the images are " + std::to_string(reference.width) + " x " +
                     std::to_string(reference.height));
  }
  // Ctrl-C heard between its steps (withProgress).
  const CompareReport r = withProgress(py::none(), "compare", [&](ProgressSink* sink) {
    return compareReport(test, reference, settings, mask ? &*mask : nullptr,
                         stdError ? &*stdError : nullptr, sink);
  });
  for (const std::string& w : r.warnings()) warn(w);  // as the command's "warning: ..." on stderr
  const CompareResult& m = r.result;
  py::dict d;  // the keys and values of `compare --json`
  d["test"] = testPath.empty() ? py::object(py::none()) : pathValue(testPath);
  d["reference"] = referencePath.empty() ? py::object(py::none()) : pathValue(referencePath);
  d["bin"] = settings.bin;
  d["width"] = r.reference.width;
  d["height"] = r.reference.height;
  py::dict channels;
  channels["R"] = channelDict(m.channel[0]);
  channels["G"] = channelDict(m.channel[1]);
  channels["B"] = channelDict(m.channel[2]);
  channels["Y"] = channelDict(m.luminance);
  channels["RGB"] = channelDict(m.rgb);
  d["channels"] = channels;
  d["clip_percentile"] = double(settings.clipPercentile);
  if (settings.clipPercentile < 100) {
    d["clip"] = std::vector<double>{r.clip.x, r.clip.y, r.clip.z};
  }
  d["black_hole_pixels"] = r.holes.pixels;
  d["black_hole_share"] = r.holes.share();
  d["compared_pixels"] = m.comparedPixels;
  d["ignored_pixels"] = m.ignoredPixels;
  d["non_finite_pixels"] = m.nonFinitePixels;
  d["non_finite_image_pixels"] = r.nonFiniteImagePixels;
  d["max_error_pixel"] = std::vector<int>{m.maxErrorX, m.maxErrorY};
  d["mean_reference_luminance"] = m.meanReferenceLuminance;
  d["mean_test_luminance"] = m.meanTestLuminance;
  d["reference_noise"] = r.referenceNoise >= 0 ? py::object(py::float_(r.referenceNoise))
                                               : py::object(py::none());
  return d;
}

/// `lightoctree lightmap`: the export with the command's settings by their
/// flag names (snake_case), defaults those of LightmapExportParams (the
/// command's), checked before any work as the command checks them.
py::dict lightmapExport(const Arg<std::string>& sceneArg, const Arg<std::string>& lightsArg,
                        const Arg<std::string>& outputArg, const py::kwargs& kw) {
  const std::string scenePath = pathArg(sceneArg.value, "scene");
  const std::string lightsPath = pathArg(lightsArg.value, "lights");
  const std::string output = pathArg(outputArg.value, "output");
  LightmapExportParams p;
  p.output = output;
  py::object sky = py::none(), skyImage = py::none(), skyMesh = py::none(), physicalSky = py::none();
  py::object progress = py::none();
  std::string directions;  // "": on, but for content "full"
  for (const auto& [key, value] : kw) {
    const std::string name = py::str(key);
    // The ranges and words of the command's flags (tools/lightmap_command.cpp).
    if (name == "progress") {
      progress = progressArg(value, name);
    } else if (name == "texel_size") {
      p.lightmap.uv.texelSize = float(numberArg(value, kPositiveNumber, name));
    } else if (name == "atlas") {
      p.lightmap.uv.atlasSize = wholeArg(value, 8, kMaxImageSide, name);
    } else if (name == "uv") {
      p.lightmap.uvSource = parseUvSource(checkChoice(textArg(value, name), {"auto", "texcoord1"}, name));
    } else if (name == "content") {
      p.content = parseAtlasContent(checkChoice(textArg(value, name), {"indirect", "full"}, name));
    } else if (name == "direct_samples") {
      p.directSamples = wholeArg(value, 1, 65536, name);
    } else if (name == "image") {
      p.rgbm = checkChoice(textArg(value, name), {"exr", "png"}, name) == "png";
    } else if (name == "preview_unlit") {
      p.preview = boolArg(value, name);
    } else if (name == "exposure") {
      p.previewExposureEv = float(numberArg(value, {-30, 30}, name));
    } else if (name == "atlas_on") {
      const std::string on = checkChoice(textArg(value, name), {"cpu", "osmesa", "egl"}, name);
      if (on == "cpu") p.atlasGl.reset();
      else p.atlasGl = parseGlBackend(on);
    } else if (name == "directions") {
      directions = checkChoice(textArg(value, name), {"on", "off"}, name);
    } else if (name == "chart_image") {
      p.chartImages = boolArg(value, name);
    } else if (name == "sky") {
      sky = py::reinterpret_borrow<py::object>(value);
    } else if (name == "sky_image") {
      skyImage = py::reinterpret_borrow<py::object>(value);
    } else if (name == "sky_mesh") {
      skyMesh = py::reinterpret_borrow<py::object>(value);
    } else if (name == "physical_sky") {
      physicalSky = py::reinterpret_borrow<py::object>(value);
    } else {
      throw InputError("lightmap: unknown setting '" + printable(name) + "'");
    }
  }
  p.directionPages = directionPagesOf(directions, p.content, "directions");
  const SceneOptions scene = sceneOptions(sky, skyImage, skyMesh, physicalSky);
  // What the command checks before any work: the folder, the name, and that
  // no file written (or removed as an earlier export's) replaces an input,
  // the inputs watched until this call ends.
  const InputsWatch watch;
  checkOutputFolder(output, "output");
  checkLightmapExportPath(output, "output");
  NamedPaths inputs = sceneInputs(scenePath, "scene");
  if (!scene.skyImage.empty()) inputs.push_back({"sky_image", scene.skyImage});
  inputs.push_back({"lights", lightsPath});
  withPythonNames([&] {  // it names the output "--output"
    checkLightmapOutputs(output, p.preview, inputs);
    return 0;
  });
  // Its steps to `progress`, and Ctrl-C at each: a stop before the commit
  // leaves no file of this export (an earlier export's set as it was).
  std::vector<std::string> sceneWarnings;  // said once the work is done (the lock held)
  std::optional<GlCall> drawing;
  if (p.atlasGl) drawing.emplace("lightmap");
  // The grid's warnings before the work (a warning turned into an error
  // stops it, nothing written), with the lock taken for them.
  p.warn = [](const std::string& w) {
    if (interpreterEnding()) return;
    py::gil_scoped_acquire locked;
    warn(pythonNames(w));
  };
  const LightmapExportResult r = withPythonNames([&] {
    return withProgress(progress, "lightmap", [&](ProgressSink* sink) {
      p.progress = sink;
      const Scene loaded = loadSceneWith(scenePath, scene);
      sceneWarnings = loaded.warnings;
      return exportLightmap(loaded, lightsPath, p);
    });
  });
  warnEach(sceneWarnings);
  const LightmapUvs& uvs = r.lightmap.uvs;
  const LightmapAtlas& atlas = r.lightmap.atlas;
  py::dict d;  // the figures of `lightmap --json`, and the files' sizes
  d["uvs"] = r.lightmap.fromTexcoord1 ? "texcoord1" : "charts";
  d["charts"] = uvs.chartCount;
  d["pages"] = atlas.pageCount;
  d["page_size"] = std::vector<int>{atlas.width, atlas.height};
  d["texel_size"] = uvs.texelSize;
  d["utilisation"] = uvs.utilisation;
  d["covered_texels"] = atlas.coveredTexels;
  d["dilated_texels"] = atlas.dilatedTexels;
  py::dict seams;
  seams["before"] = atlas.seamMismatchBefore;
  seams["after"] = atlas.seamMismatchAfter;
  d["seam_mismatch"] = seams;
  d["content"] = toString(p.content);
  d["encoding"] = p.rgbm ? "rgbm-png" : "linear-exr";
  d["rgbm_range"] = p.rgbm ? py::object(py::float_(r.rgbmRange)) : py::object(py::none());
  auto paths = [](const std::vector<std::string>& from) {
    py::list out;
    for (const std::string& path : from) out.append(pathValue(path));
    return out;
  };
  d["page_files"] = paths(r.pagePaths);
  d["direction_files"] = paths(r.directionPaths);
  d["chart_files"] = paths(r.chartPaths);
  d["gltf"] = pathValue(r.output);
  d["preview"] = r.previewPath.empty() ? py::object(py::none()) : pathValue(r.previewPath);
  d["octree_bytes"] = r.octreePoolBytes + r.octreeVdlBytes;
  d["page_file_bytes"] = r.pageFileBytes;
  d["output_bytes"] = r.outputBytes;
  d["preview_bytes"] = r.previewBytes;
  return d;
}

}  // namespace

const std::string kDefaultSppText = std::to_string(ReferenceOptions{}.spp);

PYBIND11_MODULE(lightoctree, m) {
  m.doc() =
      "Light Octree: photon-mapped global illumination baked into sparse OpenVDB grids of "
      "virtual directional lights (docs/python.md).";
  m.attr("__version__") = LO_VERSION;
  // What the calls look up once, now, while one thread imports the module
  // (see realNumberType): numbers.Real, and NumPy's C API, which pybind11
  // imports on its first use, under a static's guard.
  realNumberType = py::object(py::module_::import("numbers").attr("Real")).release();
  py::detail::npy_api::get();
  py::module_::import("atexit").attr("register")(py::cpp_function(stopCallsAtExit));
  importingProcess = ::getpid();
  ::on_exit(endForkedChild, nullptr);
  static py::handle inputError =
      py::register_exception<InputError>(m, "InputError", PyExc_ValueError);
  static py::handle ioError = py::register_exception<IoError>(m, "IoError", PyExc_OSError);
  // Tried before the two above (the last registered first): their messages
  // as valid UTF-8 (validUtf8), whatever bytes a file name put in them.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      PyErr_SetString(inputError.ptr(), validUtf8(e.what()).c_str());
    } catch (const IoError& e) {
      PyErr_SetString(ioError.ptr(), validUtf8(e.what()).c_str());
    }
  });

  py::class_<Grid, GridPtr>(m, "Grid", "A light grid: voxels with irradiance and VDLs (or SH).")
      // Only the module makes grids: pybind11 gave Grid.__new__(Grid) an
      // object allocated but never constructed, whose use crashed Python.
      .def_static("__new__", [](const py::args&, const py::kwargs&) -> py::object {
        throw py::type_error("lightoctree.Grid is made by read(), bake() and convert(), not "
                             "directly");
      })
      .def_property_readonly("size", [](const Grid& g) { return g.grid.size(); },
                             "Active voxels")
      .def_property_readonly("depth", [](const Grid& g) { return g.grid.frame.depth; })
      .def_property_readonly("voxel_size", [](const Grid& g) { return g.grid.frame.voxelSize; },
                             "Voxel edge, scene units")
      .def_property_readonly("origin", [](const Grid& g) {
        const Vec3d o = g.grid.frame.offset;
        const Vec3 c = g.grid.frame.origin;
        return py::make_tuple(o.x + c.x, o.y + c.y, o.z + c.z);
      }, "World position of voxel (0, 0, 0)'s lower corner")
      .def_property_readonly("max_vdls", [](const Grid& g) { return g.grid.maxVdls; })
      .def_property_readonly("sh_terms", [](const Grid& g) { return g.grid.shTerms; })
      .def_property_readonly("coords", [](py::object self) {
        const auto& c = self.cast<const Grid&>().grid.coords;
        return view<int32_t>(self, &c.data()->x, {c.size(), 3}, {sizeof(Coord), sizeof(int32_t)});
      }, "(N, 3) int32 voxel coordinates")
      .def_property_readonly("positions", [](const Grid& g) {
        py::array_t<double> out({g.grid.size(), size_t(3)});
        double* p = out.mutable_data();
        for (size_t v = 0; v < g.grid.size(); ++v) {
          const Vec3 c = g.grid.frame.voxelCenter(g.grid.coords[v]);
          p[3 * v] = g.grid.frame.offset.x + c.x;
          p[3 * v + 1] = g.grid.frame.offset.y + c.y;
          p[3 * v + 2] = g.grid.frame.offset.z + c.z;
        }
        return out;
      }, "(N, 3) float64 voxel centres, world space (a copy)")
      .def_property_readonly("normals", [](py::object self) { return vec3s(self, self.cast<const Grid&>().grid.normals); },
                             "(N, 3) unit normals")
      .def_property_readonly("irradiance", [](py::object self) { return vec3s(self, self.cast<const Grid&>().grid.irradiance); },
                             "(N, 3) RGB irradiance, W/m^2")
      .def_property_readonly("noise", [](py::object self) {
        const auto& n = self.cast<const Grid&>().grid.noise;
        return view<float>(self, n.data(), {n.size()}, {sizeof(float)});
      }, "(N,) relative standard error of each voxel's estimate")
      .def_property_readonly("vdl_count", [](py::object self) {
        const auto& c = self.cast<const Grid&>().grid.vdlCount;
        return view<uint8_t>(self, c.data(), {c.size()}, {sizeof(uint8_t)});
      }, "(N,) VDLs used per voxel")
      .def_property_readonly("vdl_irradiance", [](py::object self) {
        const VdlGrid& g = self.cast<const Grid&>().grid;
        const size_t k = size_t(g.maxVdls);
        return view<float>(self, &g.vdls.data()->irradiance.x, {g.size(), k, 3},
                           {k * sizeof(Vdl), sizeof(Vdl), sizeof(float)});
      }, "(N, max_vdls, 3) RGB irradiance of each VDL, strongest first")
      .def_property_readonly("vdl_direction", [](py::object self) {
        const VdlGrid& g = self.cast<const Grid&>().grid;
        const size_t k = size_t(g.maxVdls);
        return view<float>(self, &g.vdls.data()->direction.x, {g.size(), k, 3},
                           {k * sizeof(Vdl), sizeof(Vdl), sizeof(float)});
      }, "(N, max_vdls, 3) unit direction of each VDL, towards the light")
      .def_property_readonly("stats", [](const Grid& g) { return g.stats; },
                             "The bake's figures (empty for a grid read from a file)")
      .def("__repr__", [](const Grid& g) {
        return "<lightoctree.Grid: " + std::to_string(g.grid.size()) + " voxels, depth " +
               std::to_string(g.grid.frame.depth) + ", " + std::to_string(g.grid.maxVdls) +
               " VDL slots>";
      });

  m.def("bake", inCLocale(&bakeScene), py::arg("scene"), py::arg("depth") = "auto", py::arg("photons") = 0,
        py::arg("target_error") = 0.0, py::arg("seed") = 1, py::arg("knn") = BakeParams{}.knn,
        py::arg("vdls") = "4", py::arg("include_direct") = false, py::arg("target_light") = "seen",
        py::arg("progress") = py::none(), py::arg("representation") = "vdl",
        py::arg("sky") = py::none(), py::arg("sky_image") = py::none(),
        py::arg("sky_mesh") = py::none(), py::arg("physical_sky") = py::none(),
        "Bakes a scene (.gltf, .glb, .obj) as `lightoctree bake` does: photons until the noise "
        "figure reaches target_error (default 0.07), or a fixed number of photons; target_light "
        "'seen' (the noise of the light a viewer sees) or 'indirect' (of the indirect light); "
        "representation 'vdl', 'sh1' or 'sh2'; sky, sky_image, sky_mesh, physical_sky as the "
        "--sky flags (give lightmap the same). progress(task, done, total) is called as the "
        "bake goes; an exception it raises, or Ctrl-C, stops the bake and is raised.");
  m.def("read", inCLocale(&readGrid), py::arg("path"), "Reads a .vdb written by bake or convert.");
  m.def(
      "write",
      [](const Arg<std::string>& path, const Arg<Grid>& grid) {
        CLocale numbers;
        const std::string file = pathArg(path.value, "path");
        const Grid& g = gridArg(grid.value, "grid");
        checkOutputFile(file, "path", ".vdb");
        withProgress(py::none(), "write", [&](ProgressSink*) {
          writeVdlGrid(file, g.grid, g.meta);
          return 0;
        });
      },
      py::arg("path"), py::arg("grid"),
      "Writes the grid as a .vdb (atomically; a grid the readers would refuse is not written).");
  m.def("inspect", inCLocale(&inspectFile), py::arg("path"),
        "The checks `lightoctree inspect` runs: {'ok', 'checks': [{'name', 'passed', 'detail'}], ...}.");
  m.def("convert", inCLocale(&convertGrid), py::arg("grid"), py::arg("depth") = 0, py::arg("vdls") = "",
        py::arg("scene") = "",
        "Another depth (a finer one needs the scene) or VDL count, as `lightoctree convert`.");
  m.def("lookup", inCLocale(&lookup), py::arg("grid"), py::arg("points"), py::arg("normals"),
        "Irradiance E(p, n) at world points with unit normals, (N, 3) each: the renderer's "
        "octree lookup on the CPU.");
  m.def("render", inCLocale(&renderImage), py::arg("scene"), py::arg("grid"), py::arg("width") = 400,
        py::arg("height") = 300, py::arg("mode") = "full",
        "The scene lit by the grid from its camera, as `lightoctree render` draws it (OSMesa): "
        "linear RGB, shape (height, width, 3). Keywords as the command's flags, defaults the "
        "same: interpolation, specular, reflections, area_lights, cosine_correction (bool); "
        "lighting ('octree' | 'atlas'), texels ('compact' | 'half' | 'float'); supersample, vdls, "
        "emitter_lights, shadow_map_size (int); tolerance, free_space_tolerance (0..1); "
        "progress: a callable (task, done, total) told of the set-up and each frame.");
  m.def("reference", inCLocale(&referenceImage), py::arg("scene"), py::arg("width") = ReferenceOptions{}.width,
        py::arg("height") = ReferenceOptions{}.height,
        // None: not given (it excludes time_budget); shown as the command's default.
        py::arg_v("spp", py::none(), kDefaultSppText.c_str()),
        py::arg("part") = ReferenceOptions{}.part, py::arg("seed") = ReferenceOptions{}.seed,
        py::arg("max_bounces") = ReferenceOptions{}.maxBounces, py::arg("camera") = py::none(),
        py::arg("eye") = py::none(), py::arg("target") = py::none(), py::arg("fov") = py::none(),
        py::arg("time_budget") = py::none(), py::arg("std_error") = false,
        py::arg("progress") = py::none(), py::arg("sky") = py::none(),
        py::arg("sky_image") = py::none(), py::arg("sky_mesh") = py::none(),
        py::arg("physical_sky") = py::none(),
        "The path-traced ground truth, as `lightoctree reference` renders it (the same flags, "
        "defaults and camera: the scene's first camera or `camera` by name, else the scene "
        "framed; eye and target as x, y, z; fov in degrees): linear RGB, shape (height, width, "
        "3); with std_error=True (image, per-pixel standard error). part 'full' | 'direct' | "
        "'indirect' | 'irradiance'; spp (default 64), or time_budget (seconds): passes of 1 spp "
        "until it runs out, not both. progress(task, done, total) is called as it goes; an exception it raises, or "
        "Ctrl-C, stops the work and is raised.");
  m.def("compare", inCLocale(&compareImagesArg), py::arg("test"), py::arg("reference"),
        py::arg("bin") = CompareSettings{}.bin,
        py::arg("clip_percentile") = double(CompareSettings{}.clipPercentile),
        py::arg("mask") = py::none(), py::arg("ignore_background") = CompareSettings{}.ignoreBackground,
        py::arg("reference_error") = py::none(),
        "The error of a test image against a reference, as `lightoctree compare --json` reports "
        "it (the same keys and values): images, mask and reference_error (the reference's "
        "standard error) as paths or arrays of shape (height, width, 3). Black holes are "
        "judged first, then both images clipped at the reference's clip_percentile, then "
        "binned (mask and standard error alike) over bin x bin blocks.");
  m.def("lightmap", inCLocale(&lightmapExport), py::arg("scene"), py::arg("lights"), py::arg("output"),
        "Lightmaps from a baked grid file, as `lightoctree lightmap SCENE LIGHTS -o OUTPUT` "
        "writes them (the same files; an output that would replace an input is refused): "
        "OUTPUT .glb or .gltf, the pages beside it. Keywords as the command's flags, defaults "
        "the same: texel_size (0 = a quarter voxel), atlas (1024), uv ('auto' | 'texcoord1'; "
        "default TEXCOORD_1 when the scene has one), content ('indirect' | 'full'), "
        "direct_samples (64), image ('exr' | 'png'), preview_unlit (False), exposure (0), "
        "atlas_on ('cpu' | 'osmesa' | 'egl'), directions ('on' | 'off'), chart_image (False), "
        "sky, sky_image, sky_mesh, physical_sky. progress(task, done, total) is called at each "
        "step; an exception it raises, or Ctrl-C, stops the export and is raised, and no file "
        "of it is left (an earlier export's files stay as they were). Returns what it wrote: "
        "the figures of `lightmap --json` (page_files, gltf, pages, texel_size, ...) and the "
        "files' bytes.");
  m.def("read_image", inCLocale(&readImageFile), py::arg("path"),
        "An image file: EXR as linear floats, PNG decoded from sRGB; shape (height, width, 3).");
}

}  // namespace lo::python
