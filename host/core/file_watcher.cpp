#include "kiln/file_watcher.hpp"

#include <fcntl.h>
#include <sys/inotify.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>

#include "kiln/hash.hpp"
#include "kiln/log.hpp"

namespace fs = std::filesystem;

namespace kiln {

namespace {

uint64_t hashFile(const fs::path& p, bool& ok) {
    std::ifstream in(p, std::ios::binary);
    ok = bool(in);
    uint64_t h = kFnvOffsetBasis;
    char buf[65536];
    while (in) {
        in.read(buf, sizeof buf);
        h = fnv1a(buf, static_cast<size_t>(in.gcount()), h);
    }
    return h;
}

uint64_t inodeOf(const fs::path& p) {
    struct stat st {};
    return ::stat(p.c_str(), &st) == 0 ? uint64_t(st.st_ino) : 0;
}

}  // namespace

FileWatcher::FileWatcher(std::chrono::milliseconds debounce) : debounce_(debounce) {
    fd_ = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
    if (fd_ < 0) log::warn("inotify unavailable (", std::strerror(errno), "): polling files every 100 ms instead");
}

FileWatcher::~FileWatcher() {
    if (fd_ >= 0) ::close(fd_);
}

bool FileWatcher::isNoise(const std::string& name) {
    if (name.empty() || name[0] == '.' || name == "4913") return true;
    if (name.back() == '~') return true;
    for (const char* ext : {".swp", ".swx", ".swo", ".tmp"})
        if (name.size() > std::strlen(ext) && name.ends_with(ext)) return true;
    return false;
}

bool FileWatcher::watch(const fs::path& dirIn, Depth depth, const std::string& extension) {
    std::error_code ec;
    fs::path dir = fs::weakly_canonical(dirIn, ec);
    if (ec || !fs::is_directory(dir, ec)) return false;
    roots_.push_back({dir, depth, extension});
    addDirectory(roots_.back());
    return true;
}

void FileWatcher::addDirectory(const Watched& how, bool firstSight) {
    std::error_code ec;
    if (fd_ >= 0) {
        const uint32_t mask = IN_CLOSE_WRITE | IN_MOVED_TO | IN_CREATE | IN_DELETE | IN_DELETE_SELF | IN_MOVE_SELF;
        int wd = inotify_add_watch(fd_, how.dir.c_str(), mask);
        // One inotify watch a directory: watched two ways, it is watched the wider.
        if (wd >= 0) {
            auto [it, added] = watches_.try_emplace(wd, how);
            if (!added) {
                if (how.depth == Depth::Recursive) it->second.depth = Depth::Recursive;
                if (how.extension != it->second.extension) it->second.extension.clear();
            }
        }
    }
    for (auto& entry : fs::directory_iterator(how.dir, ec)) {
        if (entry.is_directory(ec)) {
            if (how.depth == Depth::Recursive) addDirectory({entry.path(), how.depth, how.extension}, firstSight);
        } else if (!how.covers(entry.path()) || !entry.is_regular_file(ec)) {
            continue;
        } else if (!firstSight) {
            noteEvent(entry.path());
        } else if (!isNoise(entry.path().filename().string())) {
            bool ok = false;
            Known k;
            k.hash = hashFile(entry.path(), ok);
            k.mtime = fs::last_write_time(entry.path(), ec);
            k.size = fs::file_size(entry.path(), ec);
            k.inode = inodeOf(entry.path());
            if (ok) known_[entry.path()] = k;
        }
    }
}

bool FileWatcher::isWatched(const fs::path& dir) const {
    for (auto& [wd, watched] : watches_)
        if (watched.dir == dir) return true;
    return false;
}

void FileWatcher::noteEvent(const fs::path& file, bool complete) {
    if (isNoise(file.filename().string())) return;
    pending_[file] = complete ? Clock::now() : Clock::now() + debounce_;
}

void FileWatcher::rescan() {
    // After an overflow (or in polling mode): anything whose identity changed is an event.
    for (const Watched& root : roots_) {
        std::error_code ec;
        for (auto it = fs::recursive_directory_iterator(root.dir, ec); it != fs::recursive_directory_iterator();
             it.increment(ec)) {
            if (ec) break;
            if (root.depth == Depth::ThisDirectory) it.disable_recursion_pending();
            if (!root.covers(it->path()) || !it->is_regular_file(ec) || isNoise(it->path().filename().string()))
                continue;
            auto found = known_.find(it->path());
            const auto mtime = fs::last_write_time(it->path(), ec);
            const auto size = fs::file_size(it->path(), ec);
            const auto inode = inodeOf(it->path());
            if (found == known_.end() || found->second.mtime != mtime || found->second.size != size ||
                found->second.inode != inode)
                noteEvent(it->path());
        }
    }
}

std::vector<fs::path> FileWatcher::poll() {
    if (fd_ >= 0) {
        readEvents();
        // A root has no parent watch to announce its return (shaders/ deleted and
        // checked out again): look for it while it is gone.
        if (Clock::now() - lastRootCheck_ > std::chrono::milliseconds(250)) {
            lastRootCheck_ = Clock::now();
            for (const Watched& root : roots_) {
                std::error_code ec;
                if (isWatched(root.dir) || !fs::is_directory(root.dir, ec)) continue;
                log::info("file watcher: ", root.dir.string(), " is back; watching it again");
                addDirectory(root, false);
            }
        }
    } else if (Clock::now() - lastScan_ > std::chrono::milliseconds(100)) {
        lastScan_ = Clock::now();
        rescan();
    }
    return settledChanges();
}

void FileWatcher::readEvents() {
    alignas(inotify_event) char buf[16384];
    for (;;) {
        const ssize_t n = ::read(fd_, buf, sizeof buf);
        if (n <= 0) return;
        for (char* p = buf; p < buf + n;) {
            auto* e = reinterpret_cast<inotify_event*>(p);
            p += sizeof(inotify_event) + e->len;
            if (e->mask & IN_Q_OVERFLOW) {
                log::warn("file watcher: event queue overflowed; rescanning");
                rescan();
                continue;
            }
            auto dir = watches_.find(e->wd);
            if (dir == watches_.end()) continue;
            if (e->mask & (IN_DELETE_SELF | IN_MOVE_SELF | IN_IGNORED)) {
                watches_.erase(dir);  // gone: re-added if it comes back (IN_CREATE on the parent)
                continue;
            }
            if (e->len == 0) continue;
            const fs::path path = dir->second.dir / e->name;
            if (e->mask & IN_ISDIR) {
                if ((e->mask & (IN_CREATE | IN_MOVED_TO)) && dir->second.depth == Depth::Recursive) {
                    addDirectory({path, Depth::Recursive, dir->second.extension});
                    rescan();  // files written before the watch existed
                }
                continue;
            }
            // IN_CREATE alone may be a half-written file: wait for CLOSE_WRITE.
            // Closed after writing or renamed into place: the file is whole, due now.
            if ((e->mask & (IN_CLOSE_WRITE | IN_MOVED_TO)) && dir->second.covers(path)) noteEvent(path, true);
        }
    }
}

std::vector<fs::path> FileWatcher::settledChanges() {
    std::vector<fs::path> settled;
    const auto now = Clock::now();
    for (auto it = pending_.begin(); it != pending_.end();) {
        if (now < it->second) {
            ++it;
            continue;
        }
        const fs::path path = it->first;
        it = pending_.erase(it);
        bool ok = false;
        Known k;
        k.hash = hashFile(path, ok);
        if (!ok) continue;  // deleted again meanwhile
        std::error_code ec;
        k.mtime = fs::last_write_time(path, ec);
        k.size = fs::file_size(path, ec);
        k.inode = inodeOf(path);
        auto found = known_.find(path);
        const bool changed = found == known_.end() || found->second.hash != k.hash;
        known_[path] = k;
        if (changed) settled.push_back(path);
    }
    return settled;
}

}  // namespace kiln
