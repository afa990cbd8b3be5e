// The `elastic._elastic` extension module: exceptions, progress and the module's entry. The
// geometry (meshes, surfaces, regions) is bound in bind_geometry.cpp, the map and what is measured
// and pasted through it in bind_map.cpp; the Python package (tools/python/elastic) re-exports them.
#include <pybind11/pybind11.h>

#include <chrono>
#include <condition_variable>
#include <thread>

#include "elastic/core/error.h"
#include "session.h"

namespace elastic::python {

ProgressCallback PythonProgress::callback() {
  return [this](const Progress& progress) {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (error_ || stopped_) {
      return false;
    }
    const py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) {  // Ctrl-C: KeyboardInterrupt is now pending
      error_ = std::make_exception_ptr(py::error_already_set());
      return false;
    }
    if (callable_.is_none()) {
      return true;
    }
    try {
      const py::object answer = callable_(std::string(progress.stage), progress.iteration,
                                          progress.total, progress.energy, progress.gradient);
      if (!answer.is_none() && !answer.cast<bool>()) {
        stopped_ = true;
        return false;
      }
    } catch (...) {
      error_ = std::current_exception();
      return false;
    }
    return true;
  };
}

void PythonProgress::rethrow() {
  if (error_) {
    std::exception_ptr error = error_;
    error_ = nullptr;
    std::rethrow_exception(error);
  }
}

namespace {

// Works of run_interruptible still running (a Ctrl-C left them behind). The interpreter's exit
// waits for them (wait_for_abandoned_works, registered with atexit): a work that outlived the
// interpreter would free its surfaces after the libraries' statics are gone.
struct RunningWorks {
  std::mutex mutex;
  std::condition_variable none_left;
  int count = 0;
};

RunningWorks& running_works() {
  static auto* works = new RunningWorks();  // never destroyed: threads may still use it at exit
  return *works;
}

void wait_for_abandoned_works() {
  const py::gil_scoped_release release;
  RunningWorks& works = running_works();
  std::unique_lock<std::mutex> lock(works.mutex);
  works.none_left.wait(lock, [&] { return works.count == 0; });
}

}  // namespace

void run_interruptible(std::function<void()> work) {
  struct Shared {
    std::mutex mutex;
    std::condition_variable done_signal;
    bool done = false;
    std::exception_ptr error;
  };
  auto shared = std::make_shared<Shared>();
  {
    const std::lock_guard<std::mutex> lock(running_works().mutex);
    ++running_works().count;
  }
  std::thread worker([shared, job = std::move(work)]() mutable {
    std::exception_ptr error;
    try {
      job();
    } catch (...) {
      error = std::current_exception();
    }
    // What the work holds (surfaces, Embree scenes) is released here, before the caller hears it
    // is done: released later, by a thread nobody waits for, it could outlive the interpreter
    // and the libraries' own statics (an Embree mutex at exit aborted the process).
    job = nullptr;
    {
      const std::lock_guard<std::mutex> lock(shared->mutex);
      shared->error = error;
      shared->done = true;
      shared->done_signal.notify_all();
    }
    RunningWorks& works = running_works();
    const std::lock_guard<std::mutex> lock(works.mutex);
    --works.count;
    works.none_left.notify_all();
  });
  for (;;) {
    {
      const py::gil_scoped_release release;
      std::unique_lock<std::mutex> lock(shared->mutex);
      if (shared->done_signal.wait_for(lock, std::chrono::milliseconds(50),
                                       [&] { return shared->done; })) {
        break;
      }
    }
    if (PyErr_CheckSignals() != 0) {
      worker.detach();  // the work goes on unseen and frees what it owns
      throw py::error_already_set();
    }
  }
  {
    const py::gil_scoped_release release;
    worker.join();
  }
  if (shared->error) {
    std::rethrow_exception(shared->error);
  }
}

namespace {

// elastic.Error and its three kinds, each also a subclass of the Python exception a caller would
// catch for it: invalid input -> ValueError, files -> OSError, numerics -> ArithmeticError.
void bind_exceptions(py::module_& m) {
  static py::handle base, invalid, io, numerical;
  const auto make = [&](const char* name, py::tuple bases, const char* doc) {
    const std::string qualified = std::string("elastic.") + name;
    py::handle type(PyErr_NewExceptionWithDoc(qualified.c_str(), doc, bases.ptr(), nullptr));
    if (!type) {
      throw py::error_already_set();
    }
    m.attr(name) = type;
    return type;
  };
  base = make("Error", py::make_tuple(py::handle(PyExc_RuntimeError)),
              "Base of every error of the library: the message names the input and the problem.");
  invalid =
      make("InvalidInputError", py::make_tuple(base, py::handle(PyExc_ValueError)),
           "An input is readable but not acceptable (malformed, non-manifold, out of range).");
  io = make("IoError", py::make_tuple(base, py::handle(PyExc_OSError)),
            "A file could not be opened, read or written.");
  numerical = make("NumericalError", py::make_tuple(base, py::handle(PyExc_ArithmeticError)),
                   "A numerical computation failed on valid input.");
  // pybind11's translator type takes the exception_ptr by value.
  // NOLINTNEXTLINE(performance-unnecessary-value-param)
  py::register_exception_translator([](std::exception_ptr error) {
    try {
      if (error) {
        std::rethrow_exception(error);
      }
    } catch (const InvalidInputError& e) {
      PyErr_SetString(invalid.ptr(), e.what());
    } catch (const IoError& e) {
      PyErr_SetString(io.ptr(), e.what());
    } catch (const NumericalError& e) {
      PyErr_SetString(numerical.ptr(), e.what());
    } catch (const Error& e) {
      PyErr_SetString(base.ptr(), e.what());
    }
  });
}

}  // namespace

}  // namespace elastic::python

PYBIND11_MODULE(_elastic, m) {
  m.doc() =
      "ElasticPaint: least-distortion maps between surface regions with a particle system "
      "(the C++ library libelastic). See docs/python.md.";
  elastic::python::bind_exceptions(m);
  elastic::python::bind_geometry(m);
  elastic::python::bind_map(m);
  pybind11::module_::import("atexit").attr("register")(
      pybind11::cpp_function(&elastic::python::wait_for_abandoned_works));
}
