// app/describe.hpp — kiln --list-modules and kiln --describe: what the pass modules
// declare, read from their declarations (the same ones the graph compiler checks a
// pipeline against), so the listing cannot disagree with what a pipeline may say.
#pragma once

#include <string>

#include "app/cli.hpp"

namespace kiln::app {

// One line per module found: its name, what it reads and writes. The exit status.
int listModules(const Options&);
// `module`'s declaration as Markdown ("all": every module, one section each, the text of
// docs/parameters.md). The exit status: 2 for a module that is not there.
int describeModules(const Options&, const std::string& module);

}  // namespace kiln::app
