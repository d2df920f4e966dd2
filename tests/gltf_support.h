/*
 * gltf_support.h -- what the suites that read back written glTF, PLY and
 * lightmap files share (test_export, test_bake): little-endian numbers,
 * and the Khronos glTF validator where scripts/setup.sh installed
 * it.  Failures go through cmocka, so these are for use inside a test.
 */
#ifndef RAD_TESTS_GLTF_SUPPORT_H
#define RAD_TESTS_GLTF_SUPPORT_H

#include <stddef.h>
#include <stdint.h>

/* Little-endian numbers at p. */
uint32_t support_le_u32(const unsigned char *p);
float support_le_f32(const unsigned char *p);

/* Run the Khronos validator (tests/validate_gltf.js, npm gltf-validator in
 * `modules`) on `count` files and assert 0 errors for each; any warning
 * must be of the kind `allowed_warning` (NULL: none expected).  Skips the
 * test (cmocka skip()) when node or the package is missing. */
void support_validate_gltf(const char *source_dir, const char *modules, const char *const *paths,
                           size_t count, const char *allowed_warning, const char *report);

#endif
