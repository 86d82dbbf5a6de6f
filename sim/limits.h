#pragma once
/// Physical limits of what rlgtherm reads and writes, in one place. The data reader refuses a
/// value outside them (SPEC section 2: file, line, column and the limit), the gyro and scenario
/// loaders refuse parameters outside theirs, and `simulate` refuses to write a trace its own
/// reader would refuse. Each is far wider than any ring laser gyro or its test chamber, so a value
/// beyond one is a mistake (a wrong unit, a typo, a corrupt file); within them every product and
/// sum the models form stays many orders of magnitude from overflow, so no inf or NaN is written.

namespace rlg::sim::limits {

/// Temperature (°C), SPEC section 2: beyond the storage range of navigation-grade gyros
/// (−55…+85 °C), with margin for chambers and heater boards.
inline constexpr double kMinTemperature_C = -80.0;
inline constexpr double kMaxTemperature_C = 150.0;
/// Widest temperature difference within that range (°C): scales the bias coefficients' limits.
inline constexpr double kTemperatureSpan_C = kMaxTemperature_C - kMinTemperature_C;

/// |bias| (°/h): 1e7 °/h = 2800 °/s, beyond the measuring range of any laser gyro (±1000 °/s =
/// 3.6e6 °/h at most); a gyro's real bias is below 100 °/h.
inline constexpr double kMaxAbsBias_dph = 1e7;

/// |time since power-on| (s): 1e9 s is 32 years, longer than any gyro runs. Times in another unit
/// (ms since 1970 is 1.7e12) are refused instead of read as seconds.
inline constexpr double kMaxAbsTime_s = 1e9;

/// Shortest sample period a scenario may ask for (s): 1 ms, faster than any gyro's thermal data
/// (the paper logged once a minute; a dithered gyro's rate output is at most a few kHz).
inline constexpr double kMinSamplePeriod_s = 1e-3;
/// Most samples in one simulated run: the trace is held in memory (~60 B per sample with four
/// sensors), so 1e8 samples (3 years at 1 s) take ~6 GB.
inline constexpr double kMaxSamplesPerRun = 1e8;

/// |heat-source power| (W): 10 kW, beyond any gyro's discharge or heater (a few W) and any lab
/// heater board.
inline constexpr double kMaxAbsPower_W = 1e4;

}  // namespace rlg::sim::limits
