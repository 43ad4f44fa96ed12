// The file watcher on real files in a temporary directory: a directory watched alone
// for one kind of file (as the app watches a scene's or pipeline's) reports its own
// files of that kind and nothing else; watched recursively, everything below it. Waits with a
// generous deadline (polling as the app does once a frame), never a fixed time.
#include <catch2/catch.hpp>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include "kiln/file_watcher.hpp"

namespace fs = std::filesystem;
using kiln::FileWatcher;

namespace {

struct WatchedTree {
    fs::path root;
    explicit WatchedTree(const std::string& name)
        : root(fs::temp_directory_path() / ("kiln-watch-" + name + "-" + std::to_string(getpid()))) {
        fs::remove_all(root);
        fs::create_directories(root / "sub");
        write("scene.json", "{}");
        write("notes.txt", "");
        write("sub/deep.json", "{}");
    }
    ~WatchedTree() {
        std::error_code ec;
        fs::remove_all(root, ec);
    }
    void write(const std::string& file, const std::string& text) const {
        std::ofstream(root / file, std::ios::trunc) << text;
    }
};

// Polls until `file` is reported (or 30 s pass) and returns every path reported by then.
std::vector<fs::path> pollUntilReported(FileWatcher& watcher, const fs::path& file) {
    std::vector<fs::path> reported;
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (std::chrono::steady_clock::now() < until) {
        for (const fs::path& p : watcher.poll()) reported.push_back(p);
        if (std::find(reported.begin(), reported.end(), file) != reported.end()) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return reported;
}

// Changes the file below the root and the .txt first, scene.json last (had the others
// been watched, they would have settled no later), and returns what was reported by the
// time scene.json was.
std::vector<fs::path> changeEveryFile(const WatchedTree& tree, FileWatcher& watcher) {
    tree.write("sub/deep.json", "{\"changed\": 1}");
    tree.write("notes.txt", "changed");
    tree.write("scene.json", "{\"changed\": 1}");
    return pollUntilReported(watcher, fs::weakly_canonical(tree.root) / "scene.json");
}

bool contains(const std::vector<fs::path>& paths, const fs::path& p) {
    return std::find(paths.begin(), paths.end(), p) != paths.end();
}

}  // namespace

TEST_CASE("a directory watched alone for .json reports its JSON files, not its subdirectories' or others", "[live]") {
    WatchedTree tree("flat");
    FileWatcher watcher;
    REQUIRE(watcher.watch(tree.root, FileWatcher::Depth::ThisDirectory, ".json"));
    const fs::path root = fs::weakly_canonical(tree.root);
    const std::vector<fs::path> reported = changeEveryFile(tree, watcher);
    CHECK(contains(reported, root / "scene.json"));
    CHECK_FALSE(contains(reported, root / "sub/deep.json"));
    CHECK_FALSE(contains(reported, root / "notes.txt"));
    // A directory made after the watch began is not watched either.
    fs::create_directories(tree.root / "later");
    tree.write("later/new.json", "{}");
    tree.write("scene.json", "{\"changed\": 2}");
    const std::vector<fs::path> after = pollUntilReported(watcher, root / "scene.json");
    CHECK(contains(after, root / "scene.json"));
    CHECK_FALSE(contains(after, root / "later/new.json"));
}

TEST_CASE("a directory watched recursively reports its subdirectories' files too", "[live]") {
    WatchedTree tree("recursive");
    FileWatcher watcher;
    REQUIRE(watcher.watch(tree.root));
    const fs::path root = fs::weakly_canonical(tree.root);
    const std::vector<fs::path> reported = changeEveryFile(tree, watcher);
    CHECK(contains(reported, root / "sub/deep.json"));
    CHECK(contains(reported, root / "notes.txt"));
    CHECK(contains(reported, root / "scene.json"));
}

TEST_CASE("a file closed after writing or renamed into place is read at once, one still being written is not",
          "[live]") {
    // A debounce of an hour: whatever is reported within the tests' deadline was reported
    // for its event, not after a quiet interval.
    WatchedTree tree("complete");
    FileWatcher watcher(std::chrono::hours(1));
    REQUIRE(watcher.usingInotify());
    REQUIRE(watcher.watch(tree.root));
    const fs::path root = fs::weakly_canonical(tree.root);

    // Written in place and closed.
    tree.write("scene.json", "{\"in place\": 1}");
    CHECK(contains(pollUntilReported(watcher, root / "scene.json"), root / "scene.json"));

    // Written to a temporary name and renamed over it, as many editors save.
    tree.write("sub/deep.json.tmp", "{\"renamed\": 1}");
    fs::rename(tree.root / "sub/deep.json.tmp", tree.root / "sub/deep.json");
    CHECK(contains(pollUntilReported(watcher, root / "sub/deep.json"), root / "sub/deep.json"));

    // Half written and still open: not reported. inotify keeps its events in order, so
    // once a file closed after it is reported, every event of the open file was read.
    {
        std::ofstream open(tree.root / "scene.json", std::ios::trunc);
        open << "{\"half\": ";
        open.flush();
        tree.write("notes.txt", "a later file, closed");
        const std::vector<fs::path> reported = pollUntilReported(watcher, root / "notes.txt");
        CHECK(contains(reported, root / "notes.txt"));
        CHECK_FALSE(contains(reported, root / "scene.json"));
        open << "2}";
    }  // closed: now whole
    CHECK(contains(pollUntilReported(watcher, root / "scene.json"), root / "scene.json"));

    // Saved again with the same bytes: nothing to reload (a closed file, so reported at
    // once had it changed; the later file below shows its event was read).
    tree.write("scene.json", "{\"half\": 2}");
    tree.write("notes.txt", "and another");
    const std::vector<fs::path> afterTouch = pollUntilReported(watcher, root / "notes.txt");
    CHECK_FALSE(contains(afterTouch, root / "scene.json"));
}
