#pragma once
/// Physical limits of what rlgtherm reads and writes, in one place. The data reader refuses a
/// value outside them (docs/data-format.md: file, line, column and the limit), the gyro and scenario
/// loaders refuse parameters outside theirs, and `simulate` refuses to write a trace its own
/// reader would refuse. Each is far wider than any ring laser gyro or its test chamber, so a value
/// beyond one is a mistake (a wrong unit, a typo, a corrupt file); within them every product and
/// sum the models form stays many orders of magnitude from overflow, so no inf or NaN is written.

namespace rlg::sim::limits {

/// Temperature (°C), docs/data-format.md: beyond the storage range of navigation-grade gyros
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

/// Columns of a data file's header (the tidy CSV, a log `import columns` reads): 65,536, far
/// beyond any gyro or chamber log (the IMU log of data/ has 9; a 1,000-channel data logger writes
/// about 1,000) and four times the widest spreadsheet (16,384 columns in Excel and LibreOffice).
/// A wider header is no log's: a file of another kind, or a line without its line breaks. The
/// readers take time linear in the columns below it (docs/performance.md).
inline constexpr int kMaxColumns = 65536;

// Gyro parameters (sim/gyro.cpp) and the same quantities in [[effects]] (sim/effects/): each
// range is far wider than any laser gyro, its sensors or its test chamber, so a value beyond
// one is a mistake, and inside them the simulation stays finite and within what the tidy CSV
// holds. (An effect's physically plausible range is its own: EffectParameter::lo, hi.)

// Heat capacity (J/K): a milligram of metal (a sensor's own lag is sensor.lag) to ten tonnes
// of aluminium.
inline constexpr double kMinCapacity = 1e-3, kMaxCapacity = 1e7;
// Conductance (W/K): 1e6 W/K is ten square metres of bonded metal joint (1e5 W/m²K).
inline constexpr double kMaxConductance = 1e6;
// Emissivity x area (m²): emissivity <= 1 times a chamber wall.
inline constexpr double kMaxEmissivityArea = 100.0;
// Source gain: the fraction of the given power that heats the nodes. Above 1 the data's power
// reads low (a heater's nominal W per % drive is a datasheet figure); ten times is a wrong
// power column, not a calibration.
inline constexpr double kMaxSourceGain = 10.0;
// Temperature sensor noise and resolution (°C): a sensor coarser than 10 °C measures nothing
// of a gyro; 1 µK is finer than any thermometer (and keeps T / resolution far inside int64).
inline constexpr double kMaxSensorNoise = 10.0, kMinResolution = 1e-6, kMaxResolution = 10.0;
// Sensor calibration offset (°C): beyond 50 °C it is a wrong sensor, not an offset.
inline constexpr double kMaxOffset = 50.0;
// Sensor lag (s): 1 ms (faster than any contact sensor) to 1e6 s (12 days).
inline constexpr double kMinLag = 1e-3, kMaxLag = 1e6;
// Bias coefficients: a term may not alone exceed the bias limit across the temperature range.
inline constexpr double kMaxBiasPerC = kMaxAbsBias_dph / kTemperatureSpan_C;
inline constexpr double kMaxBiasPerC2 = kMaxAbsBias_dph / (kTemperatureSpan_C * kTemperatureSpan_C);
// Bias per temperature rate (°/h per °C/min), with rates up to 100 °C/min.
inline constexpr double kMaxBiasPerRate = kMaxAbsBias_dph / 100.0;
// Langmuir flow: discharge currents are ~1 mA per leg, an imbalance beyond 10 mA is no gyro.
inline constexpr double kMaxCurrentImbalance_mA = 10.0, kMaxBiasPerMilliamp = kMaxAbsBias_dph / 10.0;
// Relative temperature coefficients (1/°C: Langmuir flow's c_T, discharge power drift g):
// 10 %/°C, far above any discharge's (well under 1 %/°C).
inline constexpr double kMaxRelativePerC = 0.1;
// Cavity: perimeter from a 1 cm chip to 100 m (the largest ring lasers have 16 m); expansion
// from below ULE glass (3e-8) to above any metal (2e-5); wavelength from UV to mid-IR.
inline constexpr double kMinPath_m = 0.01, kMaxPath_m = 100.0, kMinCte = 1e-10, kMaxCte = 1e-4;
inline constexpr double kMinWavelength_m = 1e-7, kMaxWavelength_m = 2e-5;
// Gyro noise: ARW 100 °/√h and bias instability / RRW / turn-on 1e4 °/h are far above a MEMS
// gyro's; with kMinSamplePeriod_s the white noise stays below the bias limit.
inline constexpr double kMaxArw = 100.0, kMaxNoise_dph = 1e4;
// Quantization (arcsec per pulse): 1e-6 arcsec is a thousandth of the finest interpolated
// fringe readout (1e-3), 3600 (1°) coarser than any.
inline constexpr double kMinQuantum = 1e-6, kMaxQuantum = 3600.0;
// Correlation time (s) of a Gauss-Markov bias: a sample period to 32 years.
inline constexpr double kMinCorrelation_s = kMinSamplePeriod_s, kMaxCorrelation_s = kMaxAbsTime_s;
// Mode hops: a PLC half-range of 1000 modes and a mode spacing beyond the temperature span
// mean no hops; a step up to the bias noise limit.
inline constexpr double kMaxRangeModes = 1000.0;
// diagnose's prior on the nominal parameters: a 1-sigma of 1000 % means nothing is known.
inline constexpr double kMaxCalibrationUncertainty = 10.0;

}  // namespace rlg::sim::limits
