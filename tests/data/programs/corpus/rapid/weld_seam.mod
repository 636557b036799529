MODULE WeldSeam1
  PERS tooldata tWeldGun:=[TRUE,[[140.5,0.0,380.2],[0.9537170,0.0000000,0.3007058,0.0000000]],[3.2,[0,0,100],[1,0,0,0],0,0,0]];
  TASK PERS wobjdata wobjFixture:=[FALSE,TRUE,"",[[1900.0,-100.0,600.0],[0.9659258,0.0000000,0.0000000,0.2588190]],[[0.0,0.0,0.0],[1.0000000,0.0000000,0.0000000,0.0000000]]];
  PERS seamdata seam1:=[0.5,0.5,[5,0,24,120,0,0,0,0,0],0.5,0,0,0,0,[5,0,24,120,0,0,0,0,0],0,0,[5,0,24,120,0,0,0,0,0],0,0,[5,0,24,120,0,0,0,0,0],0];
  PERS welddata weld1:=[10,0,[5,0,24.5,165,0,0,0,0,0],[0,0,0,0,0,0,0,0,0]];
  PERS weavedata weave1:=[1,0,3,4,0,0,0,0,0,0,0,0,0,0,0];
  CONST robtarget p10:=[[27.06,75.72,94.23],[0.2798294,-0.1980031,-0.9392297,-0.0183789],[-1,0,0,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  CONST robtarget p20:=[[34.57,15.27,39.03],[0.2664489,-0.2253526,-0.9363071,-0.0393730],[0,0,0,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  CONST robtarget p30:=[[25.60,-67.37,26.71],[0.2572346,-0.2291223,-0.9377877,-0.0434454],[0,0,0,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  CONST robtarget p40:=[[-23.26,-137.15,26.66],[0.2574246,-0.2270359,-0.9381987,-0.0443904],[0,0,0,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  CONST robtarget p50:=[[-106.07,-183.14,38.51],[0.2653070,-0.2274653,-0.9356872,-0.0485917],[0,0,0,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  CONST robtarget p60:=[[-191.78,-209.79,76.17],[0.2743188,-0.2263767,-0.9332876,-0.0497693],[0,0,0,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  PROC Seam1()
    MoveJ Offs(p10,0,0,80),v1000,z50,tWeldGun\WObj:=wobjFixture;
    ArcLStart p10,v200,seam1,weld1,fine,tWeldGun\WObj:=wobjFixture;
    ArcL p20,v200,seam1,weld1\Weave:=weave1,z1,tWeldGun\WObj:=wobjFixture;
    ArcC p30,p40,v200,seam1,weld1\Weave:=weave1,z1,tWeldGun\WObj:=wobjFixture;
    ArcL p50,v200,seam1,weld1\Weave:=weave1,z1,tWeldGun\WObj:=wobjFixture;
    ArcLEnd p60,v200,seam1,weld1,fine,tWeldGun\WObj:=wobjFixture;
    MoveL Offs(p60,0,0,80),v1000,z50,tWeldGun\WObj:=wobjFixture;
  ENDPROC
ENDMODULE
