within Modelica.Thermal;
package HeatTransfer "Lumped heat transfer (only its interfaces)"
  package Interfaces "Heat port connectors and partial models"
    partial connector HeatPort "Thermal port of 1-dim. heat transfer"
      Modelica.Units.SI.Temperature T "Port temperature";
      flow Modelica.Units.SI.HeatFlowRate Q_flow "Heat flow rate (positive if flowing from outside into the component)";
    end HeatPort;
    connector HeatPort_a "Thermal port (filled square icon)"
      extends HeatPort;
    end HeatPort_a;
    connector HeatPort_b "Thermal port (empty square icon)"
      extends HeatPort;
    end HeatPort_b;
    partial model PartialElementaryConditionalHeatPortWithoutT "An optional heat port through which the component's lost power leaves"
      parameter Boolean useHeatPort = false "= true, if the heat port is enabled";
      Modelica.Thermal.HeatTransfer.Interfaces.HeatPort_a heatPort(final Q_flow = -lossPower) if useHeatPort "Optional port to which the dissipated energy is transported as heat";
      Modelica.Units.SI.Power lossPower "Loss power leaving the component via heatPort";
    end PartialElementaryConditionalHeatPortWithoutT;
  end Interfaces;
end HeatTransfer;
