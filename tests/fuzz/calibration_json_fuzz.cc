// libFuzzer target for the calibration document's one reader (document/calibration_document.h,
// what `plumb apply`, `plumb compare` and Python's load_calibration read) and its two adapters
// (correction/calibration_file.h, peers/plumb_result.h): any byte sequence must give a
// calibration, a plumb::Error naming the key, or nlohmann's parse error, never a crash, a hang
// or a huge allocation; a calibration it gives must apply to a few samples without a NaN or an
// infinity (or say which sample it cannot correct).
#include <cstddef>
#include <cstdint>

#include <nlohmann/json.hpp>

#include "plumb/core/error.h"
#include "plumb/correction/apply.h"
#include "plumb/correction/calibration_file.h"
#include "plumb/document/calibration_document.h"
#include "plumb/peers/plumb_result.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(data, data + size);
  } catch (const nlohmann::json::exception&) {
    return 0;  // not JSON: the command names the file and the byte (io/text/json_file.h)
  }
  try {  // compare's view
    (void)plumb::peers::PlumbResultFromDocument(
        plumb::document::ReadCalibrationDocument(doc, "fuzz.json"));
  } catch (const plumb::Error&) {
  }
  try {  // apply's (and Python's): the same reader, its segments left unread
    plumb::document::ReadOptions read;
    read.still_segments = false;
    const plumb::correction::CalibrationFile file = plumb::correction::CalibrationFromDocument(
        plumb::document::ReadCalibrationDocument(doc, "fuzz.json", read));
    plumb::ImuSeries s;
    for (int k = 0; k < 3; ++k) {
      s.t_s.push_back(0.01 * k);
      s.acc.push_back(plumb::Vec3f(0.1f, -0.2f, -9.8f));
      s.gyr.push_back(plumb::Vec3f(0.01f, 0.0f, -0.01f));
      s.temp_c.push_back(25.0f);
    }
    s.acc_unit = file.acc_unit.empty() ? s.acc_unit : file.acc_unit;
    s.gyr_unit = file.gyr_unit.empty() ? s.gyr_unit : file.gyr_unit;
    plumb::correction::ApplyOptions options;
    options.uncertainty = !file.covariance_names.empty();
    const plumb::correction::CorrectedSeries out =
        plumb::correction::ApplyCalibration(file, s, options);
    for (const plumb::Vec3& f : out.f_b) {
      if (!f.allFinite()) __builtin_trap();  // ApplyCalibration promises finite corrections
    }
  } catch (const plumb::Error&) {
  }
  return 0;
}
