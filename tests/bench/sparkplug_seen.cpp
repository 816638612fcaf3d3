#include "sparkplug_seen.hpp"

#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "sparkplug_cell.hpp"

namespace fieldbridge::bench::sparkplug_cell {

Seen read_subscriber(const std::filesystem::path& decoded) {
    Seen seen;
    std::map<std::string, int> device_index;
    for (int d = 0; d < devices; ++d) device_index[device_name(d)] = d;
    std::map<std::string, std::map<std::uint64_t, int>> alias_to_point;  // device -> alias -> point
    std::ifstream in(decoded);
    std::string line;
    while (std::getline(in, line)) {
        ++seen.messages;
        auto record = nlohmann::json::parse(line, nullptr, false);
        if (record.is_discarded() || record.contains("error")) {
            ++seen.decode_errors;
            continue;
        }
        const std::string topic = record.value("topic", "");
        std::vector<std::string> levels;
        std::stringstream split(topic);
        for (std::string level; std::getline(split, level, '/');) levels.push_back(level);
        if (levels.size() < 4) continue;
        const std::string& type = levels[2];
        ++seen.by_type[type];
        const std::string device = levels.size() > 4 ? levels[4] : "";
        const auto known = device_index.find(device);
        const auto& metrics = record["metrics"];
        if (type == "DBIRTH") {
            auto& map = alias_to_point[device];
            map.clear();
            for (const auto& m : metrics) {
                if (!m["name"].is_string() || !m["alias"].is_number()) continue;
                const std::string name = m["name"];
                if (name.size() == 3 && name[0] == 'p') map[m["alias"].get<std::uint64_t>()] = std::stoi(name.substr(1));
            }
        } else if (type == "DDATA") {
            if (known == device_index.end()) {
                seen.other_ddata_metrics += metrics.size();
                continue;
            }
            const int d = known->second;
            const std::int64_t timestamp = record["timestamp"].is_number() ? record["timestamp"].get<std::int64_t>() : 0;
            seen.ddata.emplace_back(timestamp, metrics.size());
            const auto& map = alias_to_point[device];
            for (const auto& m : metrics) {
                const auto alias = m["alias"].is_number() ? m["alias"].get<std::uint64_t>() : ~std::uint64_t{0};
                const auto point = map.find(alias);
                if (point == map.end() || !m["value"].is_number()) {
                    ++seen.unmapped_metrics;
                    continue;
                }
                const int i = point->second;
                ++seen.published[change_key(round_of(m["value"].get<std::uint64_t>(), d, i), d, i)];
            }
        }
    }
    return seen;
}

}  // namespace fieldbridge::bench::sparkplug_cell
