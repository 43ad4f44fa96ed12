// kiln/json_path.hpp — JSON paths for messages ("passes[2].params.size",
// "marbles[3].position[1]") and the parse-callback tracker that knows the path of the
// value nlohmann is reading, for both loaders (pipeline files in host/graph, scene files
// in sim/). It also notes duplicate keys, which nlohmann silently resolves to the last.
// Header-only: sim/ must not depend on the host.
#pragma once

#include <nlohmann/json.hpp>

#include <cctype>
#include <set>
#include <string>
#include <vector>

#include "kiln/json_text.hpp"

namespace kiln::json_text {

// The path of `key` under `parent`; a key that is not a plain identifier is bracketed
// and quoted (params["my key"]), and a long one elided.
inline std::string keyPath(const std::string& parent, const std::string& key) {
    bool plain = !key.empty();
    for (char c : key)
        if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '$')) plain = false;
    if (!plain) return parent + "[" + elide(nlohmann::json(key).dump(), 80) + "]";
    const std::string shown = elide(key, 80);
    return parent.empty() ? shown : parent + "." + shown;
}

inline std::string indexPath(const std::string& parent, size_t i) { return parent + "[" + std::to_string(i) + "]"; }

// Pass as std::ref(tracker) to Json::parse (nlohmann copies a callback it is given by
// value). After a parse error, path() is where the parser was.
class PathTracker {
public:
    template <class Json>
    bool operator()(int /*depth*/, nlohmann::detail::parse_event_t event, Json& parsed) {
        using E = nlohmann::detail::parse_event_t;
        switch (event) {
            case E::object_start: frames_.push_back({false, 0, {}, {}}); break;
            case E::array_start: frames_.push_back({true, 0, {}, {}}); break;
            case E::key:
                if (!frames_.empty()) {
                    Frame& f = frames_.back();
                    f.key = parsed.is_string() ? parsed.template get<std::string>() : std::string();
                    if (!f.keys.insert(f.key).second) duplicates_.push_back(path());
                }
                break;
            case E::object_end:
            case E::array_end:
                if (!frames_.empty()) frames_.pop_back();
                finishValue();
                break;
            case E::value: finishValue(); break;
        }
        return true;
    }

    std::string path() const {
        std::string p;
        for (const Frame& f : frames_) p = f.array ? indexPath(p, f.index) : keyPath(p, f.key);
        return p;
    }
    // The path of every key seen a second time in the same object, in file order.
    const std::vector<std::string>& duplicateKeys() const { return duplicates_; }

private:
    struct Frame {
        bool array;
        size_t index;
        std::string key;
        std::set<std::string> keys;
    };
    void finishValue() {
        if (!frames_.empty() && frames_.back().array) ++frames_.back().index;
    }
    std::vector<Frame> frames_;
    std::vector<std::string> duplicates_;
};

}  // namespace kiln::json_text
