#include "app/editable_copy.hpp"

#include <fstream>
#include <sstream>

namespace kiln::app {

namespace fs = std::filesystem;

EditableCopy::EditableCopy(fs::path root, const fs::path& source) : root_(std::move(root)) {
    fs::remove_all(root_);
    fs::create_directories(root_ / "modules");
    fs::create_directories(root_ / "scenes");
    fs::copy(source / "shaders", root_ / "shaders", fs::copy_options::recursive);
    fs::copy(source / "pipelines", root_ / "pipelines", fs::copy_options::recursive);
    fs::copy_file(source / "scenes/cornell.json", root_ / "scenes/cornell.json");
}

EditableCopy::~EditableCopy() {
    std::error_code ec;
    fs::remove_all(root_, ec);
}

void EditableCopy::pointAt(Options& o, const std::string& pipeline) const {
    o.shaderRoot = (root_ / "shaders").string();
    o.pipeline = (root_ / "pipelines" / pipeline).string();
    o.scene = (root_ / "scenes/cornell.json").string();
    o.moduleDir = (root_ / "modules").string() + (o.moduleDir.empty() ? "" : ":" + o.moduleDir);
}

void saveByRename(const fs::path& file, const std::string& text) {
    const fs::path tmp = file.parent_path() / ("." + file.filename().string() + ".new");
    std::ofstream(tmp, std::ios::trunc | std::ios::binary) << text;
    fs::rename(tmp, file);
}

std::string readWholeFile(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

}  // namespace kiln::app
