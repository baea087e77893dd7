within Modelica.Blocks;
package Sources "Signal sources: blocks with one output and no input"
  import Modelica.Constants.pi;

  block Constant "Constant output"
    parameter Real k(start = 1) "Value of the output";
    extends Interfaces.SO;
  equation
    y = k;
  end Constant;

  block Step "A step: offset before startTime, offset + height from then on"
    parameter Real height = 1 "Height of the step";
    extends Interfaces.SignalSource;
  equation
    y = offset + (if time < startTime then 0 else height);
  end Step;

  block Ramp "A ramp from offset to offset + height during duration, from startTime"
    parameter Real height = 1 "Height of the ramp";
    parameter SI.Time duration(min = 0.0, start = 2) "Duration of the ramp (0 gives a step)";
    extends Interfaces.SignalSource;
  equation
    y = offset + (if time < startTime then 0
                  else if time < startTime + duration then (time - startTime)*height/duration
                  else height);
  end Ramp;

  block Sine "A sine wave from startTime: offset + amplitude*sin(2*pi*f*(time - startTime) + phase)"
    parameter Real amplitude = 1 "Amplitude of the sine wave";
    parameter SI.Frequency f(start = 1) "Frequency of the sine wave";
    parameter SI.Angle phase = 0 "Phase of the sine wave";
    parameter Boolean continuous = false "true: offset + amplitude*sin(phase) before startTime (continuous output)";
    extends Interfaces.SignalSource;
  equation
    if continuous then
      y = offset + amplitude*smooth(0, if time < startTime then Modelica.Math.sin(phase)
                                       else Modelica.Math.sin(2*pi*f*(time - startTime) + phase));
    else
      y = offset + (if time < startTime then 0
                    else amplitude*Modelica.Math.sin(2*pi*f*(time - startTime) + phase));
    end if;
  end Sine;

  block Cosine "A cosine wave from startTime: offset + amplitude*cos(2*pi*f*(time - startTime) + phase)"
    parameter Real amplitude = 1 "Amplitude of the cosine wave";
    parameter SI.Frequency f(start = 1) "Frequency of the cosine wave";
    parameter SI.Angle phase = 0 "Phase of the cosine wave";
    parameter Boolean continuous = false "true: offset + amplitude*cos(phase) before startTime (continuous output)";
    extends Interfaces.SignalSource;
  equation
    if continuous then
      y = offset + amplitude*smooth(0, if time < startTime then Modelica.Math.cos(phase)
                                       else Modelica.Math.cos(2*pi*f*(time - startTime) + phase));
    else
      y = offset + (if time < startTime then 0
                    else amplitude*Modelica.Math.cos(2*pi*f*(time - startTime) + phase));
    end if;
  end Cosine;

  block ExpSine "An exponentially damped sine wave from startTime"
    parameter Real amplitude = 1 "Amplitude of the sine wave";
    parameter SI.Frequency f(start = 2) "Frequency of the sine wave";
    parameter SI.Angle phase = 0 "Phase of the sine wave";
    parameter SI.Damping damping(start = 1) "Damping coefficient of the sine wave";
    extends Interfaces.SignalSource;
  equation
    y = offset + (if time < startTime then 0
                  else amplitude*Modelica.Math.exp(-(time - startTime)*damping)
                       *Modelica.Math.sin(2*pi*f*(time - startTime) + phase));
  end ExpSine;

  block Pulse "Pulses of height amplitude, width percent of each period, from startTime"
    parameter Real amplitude = 1 "Amplitude of the pulses";
    parameter Real width(final min = Modelica.Constants.small, final max = 100) = 50 "Width of a pulse in percent of the period";
    parameter SI.Time period(final min = Modelica.Constants.small, start = 1) "Time of one period";
    parameter Integer nperiod = -1 "Number of periods (< 0: infinitely many)";
    extends Interfaces.SignalSource;
  protected
    parameter SI.Time T_width = period*width/100 "Width of a pulse";
  equation
    // The time since the start of the current period, mod(time - startTime, period),
    // generates an event at every period start (Modelica 3.7.2).
    y = offset + (if time < startTime or nperiod == 0
                     or (nperiod > 0 and time >= startTime + nperiod*period) then 0
                  else if mod(time - startTime, period) < T_width then amplitude
                  else 0);
  end Pulse;

  block Trapezoid "Trapezoids: rising, staying at amplitude, falling, then zero, in each period"
    parameter Real amplitude = 1 "Amplitude of the trapezoid";
    parameter SI.Time rising(final min = 0) = 0 "Rising duration";
    parameter SI.Time width(final min = 0) = 0.5 "Duration at amplitude";
    parameter SI.Time falling(final min = 0) = 0 "Falling duration";
    parameter SI.Time period(final min = Modelica.Constants.small, start = 1) "Time of one period";
    parameter Integer nperiod = -1 "Number of periods (< 0: infinitely many)";
    extends Interfaces.SignalSource;
  protected
    parameter SI.Time T_rising = rising "End of rising within a period";
    parameter SI.Time T_width = T_rising + width "End of the width within a period";
    parameter SI.Time T_falling = T_width + falling "End of falling within a period";
    SI.Time t_period "Time since the start of the current period";
  equation
    t_period = mod(time - startTime, period);
    y = offset + (if time < startTime or nperiod == 0
                     or (nperiod > 0 and time >= startTime + nperiod*period) then 0
                  else if t_period < T_rising then amplitude*t_period/rising
                  else if t_period < T_width then amplitude
                  else if t_period < T_falling then amplitude*(T_falling - t_period)/falling
                  else 0);
  end Trapezoid;
end Sources;
