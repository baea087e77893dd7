within Modelica;
package Thermal "Thermal components (only the heat port that lossy mechanical components offer)"
end Thermal;
