/* unity_config.h - Unity's settings for the bare-metal build (UNITY_INCLUDE_CONFIG_H).
 * A header because CMake drops function-like -D definitions. No stdio on the target:
 * output goes through semihosting (semihost.c). */
#ifndef DHC_TARGET_UNITY_CONFIG_H
#define DHC_TARGET_UNITY_CONFIG_H

#define UNITY_OUTPUT_CHAR(a) dhc_target_putchar(a)
#define UNITY_OUTPUT_CHAR_HEADER_DECLARATION dhc_target_putchar(int)

#endif /* DHC_TARGET_UNITY_CONFIG_H */
