MODULE TurnTable
  PERS tooldata tWeldGun:=[TRUE,[[140.5,0.0,380.2],[0.9537170,0.0000000,0.3007058,0.0000000]],[3.2,[0,0,100],[1,0,0,0],0,0,0]];
  TASK PERS wobjdata wobjTurntable:=[FALSE,TRUE,"",[[1900.0,0.0,650.0],[1.0000000,0.0000000,0.0000000,0.0000000]],[[0.0,0.0,0.0],[1.0000000,0.0000000,0.0000000,0.0000000]]];
  CONST robtarget pA:=[[-10.32,88.79,67.56],[0.2624685,-0.0096679,-0.9641221,0.0385418],[-1,0,-1,0],[0.0,9E+09,9E+09,9E+09,9E+09,9E+09]];
  CONST robtarget pB:=[[0.17,28.61,40.04],[0.2661403,-0.0086383,-0.9637259,0.0180855],[-1,0,-1,0],[0.0,9E+09,9E+09,9E+09,9E+09,9E+09]];
  CONST robtarget pC:=[[-10.32,88.79,67.56],[0.2624685,-0.0096679,-0.9641221,0.0385418],[-1,0,-1,0],[90.0,9E+09,9E+09,9E+09,9E+09,9E+09]];
  CONST robtarget pD:=[[0.17,28.61,40.04],[0.2661403,-0.0086383,-0.9637259,0.0180855],[-1,0,-1,0],[180.0,9E+09,9E+09,9E+09,9E+09,9E+09]];
  PROC Station()
    MoveJ pA,v1000,z50,tWeldGun\WObj:=wobjTurntable;
    MoveL pB,v100,fine,tWeldGun\WObj:=wobjTurntable;
    MoveJ pC,v1000,z50,tWeldGun\WObj:=wobjTurntable;
    MoveL pD,v100,fine,tWeldGun\WObj:=wobjTurntable;
  ENDPROC
ENDMODULE
