#include "tools/ftd/source_options.hpp"

#include "tools/unit_options.hpp"

namespace ftstack::tools {

void AddSourceOptions(CLI::App& app, daemon::FtdOptions& opt) {
  app.add_option("--adc", opt.adc, "ADC backend: sim, hx711, spi, replay (a recording's bridges)")
      ->check(CLI::IsMember({"sim", "hx711", "spi", "replay"}));
  app.add_option("--replay", opt.replay,
                 "play a recording: its wrench (--adc sim) or bridge columns (--adc replay, "
                 "needs --cal: read in the unit the calibration was fitted from unless declared)")
      ->check(CLI::ExistingFile);
  AddUnitOptions(&app, &opt.replay_units);
  app.add_option("--gpiochip", opt.gpiochip, "GPIO chip for --adc hx711");
  app.add_option("--spidev", opt.spidev, "SPI device for --adc spi");
}

}  // namespace ftstack::tools
