// The state fields each built-in type's operations set alone (operations.hpp,
// FieldSetter): one entry per operation set that has any.
#include "engine/profiles/operations.hpp"
#include "engine/profiles/wtec_common.hpp"

namespace fieldbridge::engine {

std::span<const FieldSetter> field_setters(const OperationSet& operations) noexcept {
    if (operations.name == wtec_operations().name) return wtec_field_setters();
    return {};
}

}  // namespace fieldbridge::engine
