// `trimbot report DIR`: report.html of a result folder, built again from its files
// (reports/html_report.h). Bad input (not a result folder, a truncated file) exits 2 naming the
// file; the folder's report.html is left as it was.
#include <iostream>
#include <memory>
#include <string>

#include "cli/command.h"
#include "reports/html_report.h"

namespace trimbot::scenarios {

void AddReportCommand(Commands& commands) {
  auto dir = std::make_shared<std::string>();
  auto* command = commands.app().add_subcommand(
      "report", "write report.html of a result folder (run, suite, sweep, compare --out, tune) from its files");
  command->add_option("dir", *dir, "the result folder")->required();
  commands.OnRun(command, [dir] {
    WriteHtmlReport(*dir);
    std::cout << "[report] " << *dir << "/report.html" << std::endl;
    return 0;
  });
}

}  // namespace trimbot::scenarios
