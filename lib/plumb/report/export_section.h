// plumb/report/export_section.h — the page's firmware section (issue 13 point 10): what each
// export of `plumb calibrate --export FORMAT=FILE` would write from this calibration, and the
// error the firmware's correction leaves because it cannot represent all of plumb's model.
//
// The numbers are plumb/export's (exporter::PreviewExports): each firmware file is read back
// into the correction the firmware applies (per axis: scale, offset, temperature polynomial)
// and compared with plumb's full correction on the fit's still segments (exporter::Evaluate).
// The page shows them per format: RMS and largest difference per axis, accelerometer in mg
// (1 mg = 9.80665e-3 m/s^2) and gyroscope in deg/h, the largest linear term lost per unit of
// input (ppm), the effects dropped, the notes the file carries, the file itself, and the
// command that writes it. A format the export refuses shows why.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "plumb/export/export.h"

namespace plumb::report {

/// The section's HTML (<h2 id="firmware"> ...). `commands` maps a format to the command line
/// that writes it (shown when present); `note` is a line above the table ("" for none).
std::string ExportSection(const std::vector<exporter::ExportPreview>& previews,
                          const std::map<std::string, std::string>& commands,
                          const std::string& note);

}  // namespace plumb::report
