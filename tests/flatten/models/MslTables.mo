// The declarations of the Modelica Standard Library's table blocks that springc
// evaluates natively (class, function and external C names as MSL 4.1.0 writes them),
// reduced to what the tests use; no file of the MSL itself.
package Modelica
  package Constants
    final constant Real inf = 1e60;
  end Constants;
  package Blocks
    package Types
      type Smoothness = enumeration(LinearSegments, ContinuousDerivative,
        ConstantSegments, MonotoneContinuousDerivative1, MonotoneContinuousDerivative2,
        ModifiedContinuousDerivative);
      type Extrapolation = enumeration(HoldLastPoint, LastTwoPoints, Periodic,
        NoExtrapolation);
      type TimeEvents = enumeration(Always, AtDiscontinuities, NoTimeEvents);
      class ExternalCombiTimeTable
        extends ExternalObject;
        function constructor
          input String tableName;
          input String fileName;
          input Real table[:, :];
          input Real startTime;
          input Integer columns[:];
          input Smoothness smoothness;
          input Extrapolation extrapolation;
          input Real shiftTime = 0.0;
          input TimeEvents timeEvents = TimeEvents.Always;
          input Boolean verboseRead = true;
          input String delimiter = ",";
          input Integer nHeaderLines = 0;
          output ExternalCombiTimeTable externalCombiTimeTable;
        external "C" externalCombiTimeTable = ModelicaStandardTables_CombiTimeTable_init3(
          fileName, tableName, table, size(table, 1), size(table, 2), startTime, columns,
          size(columns, 1), smoothness, extrapolation, shiftTime, timeEvents,
          verboseRead, delimiter, nHeaderLines)
          annotation (Library = {"ModelicaStandardTables"});
        end constructor;
        function destructor
          input ExternalCombiTimeTable externalCombiTimeTable;
        external "C" ModelicaStandardTables_CombiTimeTable_close(externalCombiTimeTable);
        end destructor;
      end ExternalCombiTimeTable;
      class ExternalCombiTable1D
        extends ExternalObject;
        function constructor
          input String tableName;
          input String fileName;
          input Real table[:, :];
          input Integer columns[:];
          input Smoothness smoothness;
          input Extrapolation extrapolation = Extrapolation.LastTwoPoints;
          input Boolean verboseRead = true;
          input String delimiter = ",";
          input Integer nHeaderLines = 0;
          output ExternalCombiTable1D externalCombiTable1D;
        external "C" externalCombiTable1D = ModelicaStandardTables_CombiTable1D_init3(
          fileName, tableName, table, size(table, 1), size(table, 2), columns,
          size(columns, 1), smoothness, extrapolation, verboseRead, delimiter,
          nHeaderLines);
        end constructor;
        function destructor
          input ExternalCombiTable1D externalCombiTable1D;
        external "C" ModelicaStandardTables_CombiTable1D_close(externalCombiTable1D);
        end destructor;
      end ExternalCombiTable1D;
      class ExternalCombiTable2D
        extends ExternalObject;
        function constructor
          input String tableName;
          input String fileName;
          input Real table[:, :];
          input Smoothness smoothness;
          input Extrapolation extrapolation = Extrapolation.LastTwoPoints;
          input Boolean verboseRead = true;
          input String delimiter = ",";
          input Integer nHeaderLines = 0;
          output ExternalCombiTable2D externalCombiTable2D;
        external "C" externalCombiTable2D = ModelicaStandardTables_CombiTable2D_init3(
          fileName, tableName, table, size(table, 1), size(table, 2), smoothness,
          extrapolation, verboseRead, delimiter, nHeaderLines);
        end constructor;
        function destructor
          input ExternalCombiTable2D externalCombiTable2D;
        external "C" ModelicaStandardTables_CombiTable2D_close(externalCombiTable2D);
        end destructor;
      end ExternalCombiTable2D;
    end Types;
    package Tables
      package Internal
        pure function getTimeTableValue
          input Modelica.Blocks.Types.ExternalCombiTimeTable tableID;
          input Integer icol;
          input Real timeIn;
          discrete input Real nextTimeEvent;
          discrete input Real pre_nextTimeEvent;
          output Real y;
          external "C" y = ModelicaStandardTables_CombiTimeTable_getValue(tableID, icol,
            timeIn, nextTimeEvent, pre_nextTimeEvent);
        end getTimeTableValue;
        pure function getTimeTableTmax
          input Modelica.Blocks.Types.ExternalCombiTimeTable tableID;
          output Real timeMax;
          external "C" timeMax = ModelicaStandardTables_CombiTimeTable_maximumTime(tableID);
        end getTimeTableTmax;
        pure function getNextTimeEvent
          input Modelica.Blocks.Types.ExternalCombiTimeTable tableID;
          input Real timeIn;
          output Real nextTimeEvent;
          external "C" nextTimeEvent = ModelicaStandardTables_CombiTimeTable_nextTimeEvent(
            tableID, timeIn);
        end getNextTimeEvent;
        pure function getTable1DValue
          input Modelica.Blocks.Types.ExternalCombiTable1D tableID;
          input Integer icol;
          input Real u;
          output Real y;
          external "C" y = ModelicaStandardTables_CombiTable1D_getValue(tableID, icol, u);
        end getTable1DValue;
        pure function getTable1DAbscissaUmin
          input Modelica.Blocks.Types.ExternalCombiTable1D tableID;
          output Real uMin;
          external "C" uMin = ModelicaStandardTables_CombiTable1D_minimumAbscissa(tableID);
        end getTable1DAbscissaUmin;
        pure function getTable2DValue
          input Modelica.Blocks.Types.ExternalCombiTable2D tableID;
          input Real u1;
          input Real u2;
          output Real y;
          external "C" y = ModelicaStandardTables_CombiTable2D_getValue(tableID, u1, u2);
        end getTable2DValue;
      end Internal;
      block CombiTable1Ds "y = table(u), the MSL block's equations"
        parameter Real table[:, :];
        parameter Integer columns[:] = 2:size(table, 2);
        parameter Modelica.Blocks.Types.Smoothness smoothness =
          Modelica.Blocks.Types.Smoothness.LinearSegments;
        parameter Modelica.Blocks.Types.Extrapolation extrapolation =
          Modelica.Blocks.Types.Extrapolation.LastTwoPoints;
        parameter Boolean tableOnFile = false;
        parameter String fileName = "NoName";
        final parameter Real u_min = Internal.getTable1DAbscissaUmin(tableID);
        input Real u;
        output Real y[size(columns, 1)];
      protected
        parameter Modelica.Blocks.Types.ExternalCombiTable1D tableID =
          Modelica.Blocks.Types.ExternalCombiTable1D(
            if tableOnFile then "tab1" else "NoName",
            if tableOnFile then fileName else "NoName", table, columns, smoothness,
            extrapolation, false);
      equation
        for i in 1:size(columns, 1) loop
          y[i] = Internal.getTable1DValue(tableID, i, u);
        end for;
      end CombiTable1Ds;
    end Tables;
    package Sources
      block CombiTimeTable "the MSL block's declarations and equations"
        import Modelica.Blocks.Tables.Internal;
        parameter Real table[:, :];
        parameter Integer columns[:] = 2:size(table, 2);
        parameter Modelica.Blocks.Types.Smoothness smoothness =
          Modelica.Blocks.Types.Smoothness.LinearSegments;
        parameter Modelica.Blocks.Types.Extrapolation extrapolation =
          Modelica.Blocks.Types.Extrapolation.LastTwoPoints;
        parameter Real timeScale = 1;
        parameter Real offset[:] = {0};
        parameter Real startTime = 0;
        parameter Real shiftTime = startTime;
        parameter Modelica.Blocks.Types.TimeEvents timeEvents =
          Modelica.Blocks.Types.TimeEvents.Always;
        final parameter Real t_max = Internal.getTimeTableTmax(tableID) * timeScale;
        output Real y[size(columns, 1)];
      protected
        final parameter Real p_offset[size(columns, 1)] = (if size(offset, 1) == 1
          then ones(size(columns, 1)) * offset[1] else offset);
        parameter Modelica.Blocks.Types.ExternalCombiTimeTable tableID =
          Modelica.Blocks.Types.ExternalCombiTimeTable("NoName", "NoName", table,
            startTime / timeScale, columns, smoothness, extrapolation,
            shiftTime / timeScale,
            if smoothness == Modelica.Blocks.Types.Smoothness.LinearSegments then
              timeEvents elseif smoothness ==
              Modelica.Blocks.Types.Smoothness.ConstantSegments then
              Modelica.Blocks.Types.TimeEvents.Always else
              Modelica.Blocks.Types.TimeEvents.NoTimeEvents, false);
        discrete Real nextTimeEvent(start = 0, fixed = true);
        discrete Real nextTimeEventScaled(start = 0, fixed = true);
        Real timeScaled;
      equation
        timeScaled = time / timeScale;
        when {time >= pre(nextTimeEvent), initial()} then
          nextTimeEventScaled = Internal.getNextTimeEvent(tableID, timeScaled);
          nextTimeEvent = if nextTimeEventScaled < Modelica.Constants.inf then
            nextTimeEventScaled * timeScale else Modelica.Constants.inf;
        end when;
        for i in 1:size(columns, 1) loop
          y[i] = p_offset[i] + Internal.getTimeTableValue(tableID, i, timeScaled,
            nextTimeEventScaled, pre(nextTimeEventScaled));
        end for;
      end CombiTimeTable;
    end Sources;
  end Blocks;
end Modelica;
