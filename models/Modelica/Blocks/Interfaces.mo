within Modelica.Blocks;
package Interfaces "Connectors and partial blocks for input/output blocks"
  connector RealInput = input Real "Connector of a Real input signal";
  connector RealOutput = output Real "Connector of a Real output signal";
  connector BooleanInput = input Boolean "Connector of a Boolean input signal";
  connector BooleanOutput = output Boolean "Connector of a Boolean output signal";
  connector IntegerInput = input Integer "Connector of an Integer input signal";
  connector IntegerOutput = output Integer "Connector of an Integer output signal";

  partial block SO "Single output"
    extends Modelica.Blocks.Icons.Block;
    RealOutput y "Output signal";
  end SO;

  partial block MO "Multiple outputs"
    extends Modelica.Blocks.Icons.Block;
    parameter Integer nout(min = 1) = 1 "Number of outputs";
    RealOutput y[nout] "Output signals";
  end MO;

  partial block SISO "Single input, single output"
    extends Modelica.Blocks.Icons.Block;
    RealInput u "Input signal";
    RealOutput y "Output signal";
  end SISO;

  partial block SI2SO "Two inputs, single output"
    extends Modelica.Blocks.Icons.Block;
    RealInput u1 "First input signal";
    RealInput u2 "Second input signal";
    RealOutput y "Output signal";
  end SI2SO;

  partial block MISO "Multiple inputs, single output"
    extends Modelica.Blocks.Icons.Block;
    parameter Integer nin = 1 "Number of inputs";
    RealInput u[nin] "Input signals";
    RealOutput y "Output signal";
  end MISO;

  partial block SignalSource "A single output source with an offset and a start time"
    extends SO;
    parameter Real offset = 0 "Offset of the output signal";
    parameter SI.Time startTime = 0 "The output is offset for time < startTime";
  end SignalSource;
end Interfaces;
