// kiln/file_watcher.hpp — one watcher for shaders, pipelines, scenes and modules.
//
// inotify on directories (a watch on a file is lost when an editor saves by rename),
// recursive or one directory alone, polled without blocking once per frame on the render
// thread: no thread, no locks, and changes apply at a frame boundary by construction. A
// file closed after writing or renamed into place (IN_CLOSE_WRITE, IN_MOVED_TO: it is
// whole) is reported at the next poll; one only seen to differ (a rescan after a queue
// overflow, a root that came back, polling mode: it may be mid-write) once it has been
// quiet for the debounce interval. Either only if its content changed (FNV-1a of the
// bytes), so the saves of a burst between two polls are one reload and a touch is none.
// Editor noise (.swp, 4913, *~, dot-files) is ignored. On queue overflow every known file
// is re-hashed; a directory deleted and recreated (git checkout) is re-added — a watched
// root too (checked every 250 ms while it is gone), its files then compared with what
// they held before it went. Where inotify cannot be used, the same interface polls
// (nanosecond mtime + size + inode) at most every 100 ms.
#pragma once

#include <chrono>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace kiln {

class FileWatcher {
public:
    using Clock = std::chrono::steady_clock;

    explicit FileWatcher(std::chrono::milliseconds debounce = std::chrono::milliseconds(50));
    ~FileWatcher();
    FileWatcher(const FileWatcher&) = delete;
    FileWatcher& operator=(const FileWatcher&) = delete;

    // Watches `dir` and, with Depth::Recursive, its subdirectories; with an
    // `extension` (".json"), only the files that end so. Every file watched is hashed
    // when first seen: the directory a pipeline or scene file sits in may be a home
    // directory or /tmp, and is watched alone, for its JSON files (a scene in a 3.3 GB
    // /tmp took 4.9 s to start when its directory was watched whole, recursively).
    // Returns false if it does not exist.
    enum class Depth { Recursive, ThisDirectory };
    bool watch(const std::filesystem::path& dir, Depth depth = Depth::Recursive, const std::string& extension = {});
    // Files whose content changed and that are due (see the top of this file).
    std::vector<std::filesystem::path> poll();
    bool usingInotify() const { return fd_ >= 0; }

private:
    struct Known {
        uint64_t hash = 0;
        std::filesystem::file_time_type mtime{};
        uintmax_t size = 0;
        uint64_t inode = 0;
    };
    struct Watched {
        std::filesystem::path dir;
        Depth depth = Depth::Recursive;
        std::string extension;  // empty: every file
        bool covers(const std::filesystem::path& file) const {
            return extension.empty() || file.extension() == extension;
        }
    };
    // Watches `how.dir` (and its subdirectories if recursive). firstSight: its files'
    // contents are the baseline; else (a root that came back) each file is an event,
    // reported if its content changed.
    void addDirectory(const Watched& how, bool firstSight = true);
    bool isWatched(const std::filesystem::path& dir) const;
    void noteEvent(const std::filesystem::path& file, bool complete = false);
    void readEvents();  // drains inotify without blocking
    // Pending paths now due whose content changed.
    std::vector<std::filesystem::path> settledChanges();
    void rescan();
    static bool isNoise(const std::string& name);

    int fd_ = -1;
    std::chrono::milliseconds debounce_;
    std::vector<Watched> roots_;
    std::map<int, Watched> watches_;  // inotify wd → directory
    std::map<std::filesystem::path, Known> known_;  // every file seen, by content hash
    std::map<std::filesystem::path, Clock::time_point> pending_;  // path → when it is due
    Clock::time_point lastScan_{};
    Clock::time_point lastRootCheck_{};
};

}  // namespace kiln
