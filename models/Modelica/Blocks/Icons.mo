within Modelica.Blocks;
package Icons "Icons of blocks"
  partial block Block "Icon of a block" end Block;
end Icons;
