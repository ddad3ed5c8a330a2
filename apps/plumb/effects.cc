// plumb effects [NAME] — the effect catalogue: each effect's term, parameters and units.
#include <iostream>

#include "commands.h"
#include "plumb/model/registry.h"
#include "plumb/report/catalogue.h"
#include "plumb/report/json_report.h"
#include "json_output.h"

namespace plumb::cli {
namespace {

class EffectsCommand : public Command {
 public:
  explicit EffectsCommand(CLI::App& parent) {
    app_ = parent.add_subcommand("effects",
                                 "List the effects a model can be made of, with their terms, "
                                 "parameters and units");
    app_->footer("Example:\n  plumb effects --json effects.json");
    app_->add_option("NAME", name_, "Show only this effect");
    app_->add_option("--json", json_path_, "Also write the catalogue as JSON to FILE (- for stdout, the text then on stderr)")
        ->type_name("FILE");
  }

  int Run() override {
    const TextAsideForJson text_aside(json_path_);
    const auto& registry = model::Registry::Global();
    std::cout << report::CatalogueText(registry, name_);
    if (!json_path_.empty()) {
      WriteJsonOutput(json_path_, report::CatalogueJson(registry, name_));
    }
    return 0;
  }

 private:
  std::string name_;
  std::string json_path_;
};

}  // namespace

std::unique_ptr<Command> MakeEffectsCommand(CLI::App& parent) {
  return std::make_unique<EffectsCommand>(parent);
}

}  // namespace plumb::cli
