#pragma once
/// @file yaml_reader.hpp
/// Reading YAML nodes into raw fields: the kind checks (map / list / scalar),
/// unknown and duplicate keys, scalar conversion, and the key path and 1-based
/// position of everything read. Internal to the config layer.

#include <yaml-cpp/yaml.h>

#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "config/diagnostic_sink.hpp"
#include "config/parsed.hpp"
#include "config/raw_config.hpp"
#include "core/names.hpp"

namespace fieldbridge::config {

/// yaml-cpp marks are 0-based; ours are 1-based. A null mark gives @p fallback.
[[nodiscard]] Mark to_mark(const YAML::Mark& mark, Mark fallback) noexcept;

/// A node of the tree with its key path and position.
struct NodeRef {
    std::optional<YAML::Node> node;  ///< empty: the key is absent
    std::string path;
    Mark mark;  ///< of the value (of its key for a null value); of the enclosing map when absent
};

/// "a map", "a list", "a single value", "nothing".
[[nodiscard]] std::string_view kind_name(const YAML::Node& node);

/// A map node whose keys are checked on construction: a node that is not a map,
/// keys that are not allowed (with the allowed list and a likely spelling), and
/// duplicate keys are reported to the sink. A null node reads as an empty map.
/// YAML merge keys (`<<: *defaults`) are applied; keys written in the map win.
class MapReader {
public:
    /// @p ignore_extension_keys: keys starting with "x-" are skipped (the document
    /// root offers them as a place for YAML anchors).
    MapReader(const NodeRef& ref, std::initializer_list<std::string_view> allowed, DiagnosticSink& sink,
              bool ignore_extension_keys = false);
    /// A map whose keys are data (any key is allowed), e.g. mqtt.deadband.
    MapReader(const NodeRef& ref, DiagnosticSink& sink);

    [[nodiscard]] NodeRef child(std::string_view key) const;
    [[nodiscard]] std::string child_path(std::string_view key) const;
    [[nodiscard]] RawNode::State state() const noexcept { return state_; }
    [[nodiscard]] const std::string& path() const noexcept { return path_; }
    [[nodiscard]] Mark mark() const noexcept { return mark_; }
    [[nodiscard]] DiagnosticSink& sink() const noexcept { return *sink_; }

    struct Entry {
        std::string key;
        Mark key_mark;
        NodeRef value;
    };
    [[nodiscard]] const std::vector<Entry>& entries() const noexcept { return entries_; }

    /// Copies state, path and position into a raw node.
    void fill(RawNode& raw) const {
        raw.state = state_;
        raw.path = path_;
        raw.mark = mark_;
    }

private:
    void read_entries(const NodeRef& ref, const std::vector<std::string_view>* allowed);
    void add_pairs(const YAML::Node& node, const std::vector<std::string_view>* allowed, bool merged,
                   std::vector<YAML::Node>& merge_sources);

    DiagnosticSink* sink_;
    std::string path_;
    Mark mark_;
    bool ignore_extension_keys_ = false;
    RawNode::State state_ = RawNode::State::absent;
    std::vector<Entry> entries_;
};

/// Reads a scalar through @p convert (string_view -> Parsed<T>). @p what names the
/// expected value for kind errors, e.g. "a duration such as 250ms".
template <class T, class Convert>
[[nodiscard]] Field<T> read_scalar(const NodeRef& ref, DiagnosticSink& sink, std::string_view what, Convert convert) {
    Field<T> field;
    field.path = ref.path;
    field.mark = ref.mark;
    if (!ref.node) {
        return field;
    }
    const YAML::Node& node = *ref.node;
    if (!node.IsScalar()) {
        field.invalid = true;
        if (node.IsNull()) {
            sink.error(field, "has no value; expected " + std::string(what) + " (or remove the key)");
        } else {
            sink.error(field, "expected " + std::string(what) + ", got " + std::string(kind_name(node)));
        }
        return field;
    }
    Parsed<T> parsed = convert(std::string_view(node.Scalar()));
    if (!parsed) {
        field.invalid = true;
        sink.error(field, std::move(parsed.error));
        return field;
    }
    field.value = std::move(parsed.value);
    return field;
}

[[nodiscard]] Field<std::int64_t> read_int(const MapReader& map, std::string_view key);
[[nodiscard]] Field<std::chrono::milliseconds> read_duration(const MapReader& map, std::string_view key);
[[nodiscard]] Field<bool> read_bool(const MapReader& map, std::string_view key);
[[nodiscard]] Field<std::string> read_string(const MapReader& map, std::string_view key);
[[nodiscard]] Field<ListenAddress> read_listen_address(const MapReader& map, std::string_view key);

/// A closed set of spellings (pairs of name and value); an unknown one is reported
/// with the allowed list.
template <class E, class Choices>
[[nodiscard]] Field<E> read_choice(const MapReader& map, std::string_view key, const Choices& choices) {
    std::string allowed;
    for (const auto& [name, value] : choices) {
        allowed += allowed.empty() ? "" : ", ";
        allowed += name;
    }
    return read_scalar<E>(map.child(key), map.sink(), "one of " + allowed, [&](std::string_view text) {
        for (const auto& [name, value] : choices) {
            if (text == name) {
                return Parsed<E>::ok(value);
            }
        }
        return Parsed<E>::fail("'" + std::string(text) + "' is not allowed; expected one of: " + allowed);
    });
}

/// An enum of the configuration only, spelled by @p choices.
template <class E>
[[nodiscard]] Field<E> read_enum(const MapReader& map, std::string_view key,
                                 std::initializer_list<std::pair<std::string_view, E>> choices) {
    return read_choice<E>(map, key, choices);
}

/// A shared enum, spelled as its core name table says (core/names.hpp).
template <class E, std::size_t N>
[[nodiscard]] Field<E> read_enum(const MapReader& map, std::string_view key, const core::NameTable<E, N>& names) {
    return read_choice<E>(map, key, names);
}

/// A list of scalars. A null value reads as an empty list.
template <class T, class Convert>
[[nodiscard]] FieldList<T> read_list(const MapReader& map, std::string_view key, std::string_view what,
                                     Convert convert) {
    FieldList<T> list;
    const NodeRef ref = map.child(key);
    list.path = ref.path;
    list.mark = ref.mark;
    if (!ref.node) {
        return list;
    }
    const YAML::Node& node = *ref.node;
    if (node.IsNull()) {
        list.state = RawNode::State::ok;
        return list;
    }
    if (!node.IsSequence()) {
        list.state = RawNode::State::invalid;
        map.sink().error(list, "expected a list of " + std::string(what) + ", got " + std::string(kind_name(node)));
        return list;
    }
    list.state = RawNode::State::ok;
    for (std::size_t i = 0; i < node.size(); ++i) {
        const YAML::Node item = node[i];
        NodeRef item_ref{item, list.path + "[" + std::to_string(i) + "]", to_mark(item.Mark(), list.mark)};
        list.items.push_back(read_scalar<T>(item_ref, map.sink(), what, convert));
    }
    return list;
}

/// A list of maps, each read by @p parse_item(const NodeRef&, DiagnosticSink&).
template <class R, class ParseItem>
[[nodiscard]] RawSeq<R> read_seq(const MapReader& map, std::string_view key, ParseItem parse_item) {
    RawSeq<R> seq;
    const NodeRef ref = map.child(key);
    seq.path = ref.path;
    seq.mark = ref.mark;
    if (!ref.node) {
        return seq;
    }
    const YAML::Node& node = *ref.node;
    if (node.IsNull()) {
        seq.state = RawNode::State::ok;
        return seq;
    }
    if (!node.IsSequence()) {
        seq.state = RawNode::State::invalid;
        map.sink().error(seq, "expected a list, got " + std::string(kind_name(node)));
        return seq;
    }
    seq.state = RawNode::State::ok;
    for (std::size_t i = 0; i < node.size(); ++i) {
        const YAML::Node item = node[i];
        NodeRef item_ref{item, seq.path + "[" + std::to_string(i) + "]", to_mark(item.Mark(), seq.mark)};
        seq.items.push_back(parse_item(item_ref, map.sink()));
    }
    return seq;
}

}  // namespace fieldbridge::config
