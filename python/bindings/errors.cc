// plumb's errors as Python exceptions: plumb::Error -> plumb.Error (a subclass of Exception),
// plumb::InputError -> plumb.InputError (with .file and .where), plumb::InsufficientDataError
// -> plumb.InsufficientDataError, both subclasses of plumb.Error; the message is plumb's.
// A JSON document of the wrong shape (nlohmann::json's exceptions) is a plumb.Error too.
#include <nlohmann/json.hpp>

#include "common.h"
#include "plumb/core/error.h"

namespace plumb::python {

void RegisterErrors(py::module_& m) {
  static py::exception<Error> error(m, "Error", PyExc_Exception);
  error.doc() = "plumb's error: the message names the file and the place (line, byte) and what "
                "was expected.";
  static py::exception<InputError> input_error(m, "InputError", error.ptr());
  input_error.doc() = "Bad input: .file and .where (e.g. 'line 12') say where.";
  static py::exception<InsufficientDataError> insufficient(m, "InsufficientDataError", error.ptr());
  insufficient.doc() = "The data cannot support the model: the message says what to record.";
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      py::object value = py::reinterpret_borrow<py::object>(input_error.ptr())(e.what());
      value.attr("file") = e.file();
      value.attr("where") = e.where();
      PyErr_SetObject(input_error.ptr(), value.ptr());
    } catch (const InsufficientDataError& e) {
      PyErr_SetString(insufficient.ptr(), e.what());
    } catch (const Error& e) {
      PyErr_SetString(error.ptr(), e.what());
    } catch (const nlohmann::json::exception& e) {
      PyErr_SetString(error.ptr(), (std::string("JSON: ") + e.what()).c_str());
    }
  });
}

}  // namespace plumb::python
