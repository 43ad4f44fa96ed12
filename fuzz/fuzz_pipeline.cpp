// Fuzz target: pipeline parser + graph compiler (over the in-memory declarations of
// tests/graph/fake_modules.hpp). Any input must give a plan or named, bounded errors;
// a pipeline that parses must write back to text that parses again.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "graph/compiler.hpp"
#include "graph/pipeline.hpp"
#include "graph/fake_modules.hpp"

namespace {
void require(bool ok, const char* what, const std::string& detail = {}) {
    if (ok) return;
    std::fprintf(stderr, "fuzz_pipeline: invariant broken: %s\n%.2000s\n", what, detail.c_str());
    std::abort();
}
// Every error is one bounded line (messages elide what they quote).
void checkErrors(const std::string& text) {
    size_t start = 0;
    while (start < text.size()) {
        size_t end = text.find('\n', start);
        if (end == std::string::npos) end = text.size();
        require(end - start <= 2000, "an error line longer than 2000 bytes", text.substr(start, 2000));
        start = end + 1;
    }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace kiln::graph;
    const std::string text(reinterpret_cast<const char*>(data), size);
    static const CompileOptions options = test::fakeOptions();
    Result<PipelineDesc> parsed = parsePipeline(text, "pipelines/fuzz.json");
    if (parsed.ok()) {
        const std::string back = writePipeline(*parsed);
        Result<PipelineDesc> again = parsePipeline(back, "pipelines/fuzz.json");
        require(again.ok(), "a parsed pipeline written back does not parse", back + "\n" + again.errorText());
    } else {
        checkErrors(parsed.errorText());
    }
    Result<Plan> plan = compileText(text, "pipelines/fuzz.json", options);
    if (!plan.ok()) checkErrors(plan.errorText());
    return 0;
}
