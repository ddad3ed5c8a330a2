// plumb/pipeline/study_template.h — a sensitivity study's session template (schedule
// "session": a calibration document (SPEC section 6) whose segments and site the study's runs repeat),
// read for the study as `plumb sweep` and the Python module's sweep_point read it.
#pragma once

#include <string>

#include "plumb/study/study.h"

namespace plumb::pipeline {

/// When `study` names a session template (base.template_path), reads it into
/// study.template_document and sets base.template_path to the path read: a relative path is
/// taken relative to `folder` (the study file's folder; "" = the current folder). Nothing when
/// it names none. Throws plumb::InputError naming the template when it cannot be read.
void ReadSessionTemplate(study::Study& study, const std::string& folder);

}  // namespace plumb::pipeline
