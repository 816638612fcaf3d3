#include "config/yaml_documents.hpp"

#include <yaml-cpp/eventhandler.h>

#include <sstream>
#include <string>
#include <vector>

namespace fieldbridge::config {

namespace {

/// Where each document starts, and its root node.
struct DocumentMarks {
    YAML::Mark start;
    std::optional<YAML::Mark> root;
};

/// Records the marks of the documents; the nodes themselves are built by YAML::Load.
class MarkRecorder final : public YAML::EventHandler {
public:
    explicit MarkRecorder(std::vector<DocumentMarks>& documents) : documents_(documents) {}

    void OnDocumentStart(const YAML::Mark& mark) override { documents_.push_back({mark, std::nullopt}); }
    void OnDocumentEnd() override {}
    void OnNull(const YAML::Mark& mark, YAML::anchor_t) override { node(mark); }
    void OnAlias(const YAML::Mark& mark, YAML::anchor_t) override { node(mark); }
    void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t, const std::string&) override {
        node(mark);
    }
    void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                         YAML::EmitterStyle::value) override {
        node(mark);
    }
    void OnSequenceEnd() override {}
    void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
        node(mark);
    }
    void OnMapEnd() override {}

private:
    void node(const YAML::Mark& mark) {
        if (!documents_.empty() && !documents_.back().root) documents_.back().root = mark;
    }

    std::vector<DocumentMarks>& documents_;
};

/// Enough documents to know the first and whether a second follows, plus one to see
/// that the parser is stuck (yaml-cpp #1040: an empty document at the same position,
/// again and again).
constexpr std::size_t documents_read = 3;

}  // namespace

YamlDocuments read_documents(std::string_view yaml) {
    const std::string text(yaml);
    std::vector<DocumentMarks> documents;
    {
        std::istringstream stream(text);
        YAML::Parser parser(stream);
        MarkRecorder recorder(documents);
        while (documents.size() < documents_read && parser.HandleNextDocument(recorder)) {
            if (documents.size() >= 2 && documents.back().start.pos == documents[documents.size() - 2].start.pos) {
                const auto at = static_cast<std::size_t>(documents.back().start.pos);
                const unsigned char c = at < text.size() ? static_cast<unsigned char>(text[at]) : 0;
                const std::string what = c >= 0x20 && c < 0x7F ? std::string("unexpected '") + static_cast<char>(c) + "'"
                                                             : std::string("unexpected character");
                throw YAML::ParserException(documents.back().start, what + " where a value should start");
            }
        }
    }
    YamlDocuments out;
    if (!documents.empty()) out.first = YAML::Load(text);
    if (documents.size() >= 2) out.second = documents[1].root.value_or(documents[1].start);
    return out;
}

}  // namespace fieldbridge::config
