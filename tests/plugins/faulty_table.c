/* Test-only plugin libraries whose table is broken before any query, one fault per macro:
 *   FAULT_NO_ENTRY       the entry point is missing (the library exports another name);
 *   FAULT_ABI_VERSION    the table claims ABI version 99;
 *   FAULT_NULL_FUNCTION  the required `create` function is NULL. */

#include "delamesh_plugin.h"

#include <stddef.h>

#define EXPORT __attribute__((visibility("default")))

static const DmPluginV1 table = {
#if defined(FAULT_ABI_VERSION)
    .abi_version = 99,
#else
    .abi_version = DM_ABI_VERSION,
#endif
    .struct_size = sizeof(DmPluginV1),
    .name = "faulty-table",
    .kind = "test",
    .version = "0.0.0",
};

#if defined(FAULT_NO_ENTRY)
EXPORT const DmPluginV1 *not_a_delamesh_plugin(void) { return &table; }
#else
EXPORT const DmPluginV1 *delamesh_plugin_v1(void) { return &table; }
#endif
