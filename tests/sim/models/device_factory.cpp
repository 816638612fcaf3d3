#include "models/device_factory.hpp"

#include <stdexcept>
#include <string>

#include "models/excd_model.hpp"
#include "models/generic_modbus_model.hpp"
#include "models/wtec_ascii_model.hpp"
#include "models/wtec_rtu_model.hpp"
#include "models/xeg_model.hpp"

namespace fieldbridge::sim {
namespace {

constexpr std::string_view type_xeg = "hiwin-xeg";
constexpr std::string_view type_excd = "excd203mb";
constexpr std::string_view type_wtec_rtu = "wtec-rtu";
constexpr std::string_view type_wtec_ascii = "wtec-ascii";
constexpr std::string_view type_generic = "modbus";

bool excd_high_word_first(const std::string& word_order) {
    if (word_order == "high_first") return true;
    if (word_order == "low_first") return false;
    throw std::invalid_argument("excd203mb: word order \"" + word_order +
                                "\" is neither \"high_first\" nor \"low_first\"");
}

}  // namespace

std::vector<std::string_view> device_types() {
    return {type_xeg, type_excd, type_wtec_rtu, type_wtec_ascii, type_generic};
}

std::unique_ptr<BusDevice> make_device(std::string_view type, std::uint8_t address,
                                       const DeviceOptions& options) {
    if (type == type_xeg) return make_xeg(address, XegOptions{options.xeg_model});
    if (type == type_excd) {
        return make_excd(address, ExcdOptions{excd_high_word_first(options.excd_word_order)});
    }
    if (type == type_wtec_rtu) return make_wtec_rtu(address, options.wtec_stroke);
    if (type == type_wtec_ascii) return make_wtec_ascii(address, options.wtec_stroke);
    if (type == type_generic) return make_generic_modbus(address);
    if (options.definition && type == options.definition->name) {
        return std::make_unique<DefinitionModel>(address, options.definition);
    }
    throw std::invalid_argument("unknown simulated device type \"" + std::string(type) +
                                "\"; use hiwin-xeg, excd203mb, wtec-rtu, wtec-ascii, modbus or a device definition (--definitions, --definition)");
}

}  // namespace fieldbridge::sim
