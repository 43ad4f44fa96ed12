// A temporary copy of the files Kiln edits live — shaders, pipelines, the shipped scene
// and an empty modules/ folder — for the runs that edit them through the real file
// watcher: the live tests, kiln-bench-live and kiln-soak. One place sets up the copy,
// points a run at it and saves the way an editor does.
#pragma once

#include <filesystem>
#include <string>

#include "app/cli.hpp"

namespace kiln::app {

class EditableCopy {
public:
    // Copies `source` (a Kiln tree: shaders/, pipelines/, scenes/cornell.json) into
    // `root`, replacing whatever was there. Throws std::filesystem_error on failure.
    EditableCopy(std::filesystem::path root, const std::filesystem::path& source);
    ~EditableCopy();  // removes the copy
    EditableCopy(const EditableCopy&) = delete;
    EditableCopy& operator=(const EditableCopy&) = delete;

    const std::filesystem::path& root() const { return root_; }
    // Points `o` at the copy: its shaders, pipelines/<pipeline>, its scene, and its
    // modules/ ahead of the module path `o` already has.
    void pointAt(Options& o, const std::string& pipeline = "default.json") const;

private:
    std::filesystem::path root_;
};

// An editor's save: the text written to a temporary file beside `file`, then renamed
// over it (one inotify event for the file, never a half-written read).
void saveByRename(const std::filesystem::path& file, const std::string& text);
// The whole file as bytes ("" when it cannot be read).
std::string readWholeFile(const std::filesystem::path& file);

}  // namespace kiln::app
