#include "config/yaml_reader.hpp"

#include <algorithm>

#include "config/net_address.hpp"
#include "config/scalars.hpp"

namespace fieldbridge::config {

namespace {

/// Edit distance, for "did you mean" on unknown keys.
[[nodiscard]] std::size_t edit_distance(std::string_view a, std::string_view b) {
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) {
        row[j] = j;
    }
    for (std::size_t i = 1; i <= a.size(); ++i) {
        std::size_t diagonal = row[0];
        row[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const std::size_t above = row[j];
            const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + cost});
            diagonal = above;
        }
    }
    return row[b.size()];
}

[[nodiscard]] std::string unknown_key_message(std::string_view key, const std::vector<std::string_view>& allowed) {
    std::string message = "unknown key '" + std::string(key) + "'";
    std::string_view best;
    std::size_t best_distance = 3;  // farther than 2 edits is not a misspelling
    for (const auto candidate : allowed) {
        // A key that extends or shortens an allowed one ("baudrate", "init") is as
        // likely a slip as a typo.
        const bool prefix = std::min(key.size(), candidate.size()) >= 3 &&
                            (key.starts_with(candidate) || candidate.starts_with(key));
        const std::size_t d = prefix ? 1 : edit_distance(key, candidate);
        if (d < best_distance && d < std::max<std::size_t>(candidate.size(), 2)) {
            best = candidate;
            best_distance = d;
        }
    }
    if (!best.empty()) {
        message += " (did you mean '" + std::string(best) + "'?)";
    }
    message += "; allowed keys here: ";
    for (std::size_t i = 0; i < allowed.size(); ++i) {
        message += (i == 0 ? "" : ", ") + std::string(allowed[i]);
    }
    return message;
}

}  // namespace

Mark to_mark(const YAML::Mark& mark, Mark fallback) noexcept {
    if (mark.is_null() || mark.line < 0 || mark.column < 0) {
        return fallback;
    }
    return Mark{mark.line + 1, mark.column + 1};
}

std::string_view kind_name(const YAML::Node& node) {
    switch (node.Type()) {
        case YAML::NodeType::Map: return "a map";
        case YAML::NodeType::Sequence: return "a list";
        case YAML::NodeType::Scalar: return "a single value";
        case YAML::NodeType::Null: return "nothing";
        case YAML::NodeType::Undefined: break;
    }
    return "nothing";
}

MapReader::MapReader(const NodeRef& ref, std::initializer_list<std::string_view> allowed, DiagnosticSink& sink,
                     bool ignore_extension_keys)
    : sink_(&sink), path_(ref.path), mark_(ref.mark), ignore_extension_keys_(ignore_extension_keys) {
    const std::vector<std::string_view> allowed_keys(allowed);
    read_entries(ref, &allowed_keys);
}

MapReader::MapReader(const NodeRef& ref, DiagnosticSink& sink) : sink_(&sink), path_(ref.path), mark_(ref.mark) {
    read_entries(ref, nullptr);
}

void MapReader::read_entries(const NodeRef& ref, const std::vector<std::string_view>* allowed) {
    if (!ref.node) {
        state_ = RawNode::State::absent;
        return;
    }
    const YAML::Node& node = *ref.node;
    if (node.IsNull()) {
        state_ = RawNode::State::ok;  // "key:" with nothing under it: an empty map
        return;
    }
    if (!node.IsMap()) {
        state_ = RawNode::State::invalid;
        sink_->error(mark_, path_, "expected a map (key: value pairs), got " + std::string(kind_name(node)));
        return;
    }
    state_ = RawNode::State::ok;
    std::vector<YAML::Node> merge_sources;
    add_pairs(node, allowed, false, merge_sources);
    // YAML merge keys ("<<: *defaults"), which yaml-cpp leaves to the application:
    // keys written in the map win, then earlier sources over later ones.
    constexpr std::size_t max_merge_sources = 64;  // bounds alias cycles and fan-out
    for (std::size_t i = 0; i < merge_sources.size() && i < max_merge_sources; ++i) {
        const YAML::Node source = merge_sources[i];  // a copy: add_pairs may grow the list
        add_pairs(source, allowed, true, merge_sources);
    }
}

void MapReader::add_pairs(const YAML::Node& node, const std::vector<std::string_view>* allowed, bool merged,
                          std::vector<YAML::Node>& merge_sources) {
    for (auto it = node.begin(); it != node.end(); ++it) {
        const YAML::Node key_node = it->first;
        const YAML::Node value = it->second;
        const Mark key_mark = to_mark(key_node.Mark(), mark_);
        if (!key_node.IsScalar()) {
            sink_->error(key_mark, path_, "a key must be a plain name, got " + std::string(kind_name(key_node)));
            continue;
        }
        const std::string key = key_node.Scalar();
        const std::string path = child_path(key);
        if (key == "<<") {
            if (value.IsMap()) {
                merge_sources.push_back(value);
                continue;
            }
            const bool maps = value.IsSequence() && std::all_of(value.begin(), value.end(), [](const YAML::Node& n) {
                                  return n.IsMap();
                              });
            if (!maps) {
                sink_->error(key_mark, path, "a merge key needs a map or a list of maps, e.g. <<: *defaults");
                continue;
            }
            for (const auto& source : value) {
                merge_sources.push_back(source);
            }
            continue;
        }
        if (ignore_extension_keys_ && key.starts_with("x-")) {
            continue;  // a place for YAML anchors, ignored by design
        }
        if (allowed != nullptr && std::find(allowed->begin(), allowed->end(), key) == allowed->end()) {
            sink_->error(key_mark, path, unknown_key_message(key, *allowed));
            continue;
        }
        const auto earlier = std::find_if(entries_.begin(), entries_.end(), [&](const Entry& e) { return e.key == key; });
        if (earlier != entries_.end()) {
            if (!merged) {
                sink_->error(key_mark, path,
                             "duplicate key; it is already set at line " + std::to_string(earlier->key_mark.line) +
                                 " (remove one of them)");
            }
            continue;
        }
        // A null value has no useful position of its own (yaml-cpp puts it after the
        // key): point at the key instead.
        const Mark value_mark = value.IsNull() ? key_mark : to_mark(value.Mark(), key_mark);
        entries_.push_back(Entry{key, key_mark, NodeRef{value, path, value_mark}});
    }
}

std::string MapReader::child_path(std::string_view key) const {
    return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
}

NodeRef MapReader::child(std::string_view key) const {
    const auto it = std::find_if(entries_.begin(), entries_.end(), [&](const Entry& e) { return e.key == key; });
    if (it == entries_.end()) {
        return NodeRef{std::nullopt, child_path(key), mark_};
    }
    return it->value;
}

Field<std::int64_t> read_int(const MapReader& map, std::string_view key) {
    return read_scalar<std::int64_t>(map.child(key), map.sink(), "an integer", parse_integer);
}

Field<std::chrono::milliseconds> read_duration(const MapReader& map, std::string_view key) {
    return read_scalar<std::chrono::milliseconds>(map.child(key), map.sink(), "a duration such as 250ms or 2s",
                                                  parse_duration);
}

Field<bool> read_bool(const MapReader& map, std::string_view key) {
    return read_scalar<bool>(map.child(key), map.sink(), "true or false", parse_bool);
}

Field<std::string> read_string(const MapReader& map, std::string_view key) {
    return read_scalar<std::string>(map.child(key), map.sink(), "a text value",
                                    [](std::string_view text) { return Parsed<std::string>::ok(std::string(text)); });
}

Field<ListenAddress> read_listen_address(const MapReader& map, std::string_view key) {
    return read_scalar<ListenAddress>(map.child(key), map.sink(), "an address such as 127.0.0.1:502",
                                      parse_listen_address);
}

}  // namespace fieldbridge::config
