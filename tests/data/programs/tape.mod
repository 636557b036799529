MODULE tape
  ! tape laying: approach, lay, arc, retract (hand-written, RAPID syntax)
  PERS tooldata thead:=[TRUE,[[0,0,350],[1,0,0,0]],[300,[0,0,150],[1,0,0,0],0,0,0]];
  TASK PERS wobjdata wtable:=[FALSE,TRUE,"",[[500,0,0],[1,0,0,0]],[[0,-20,0],[1,0,0,0]]];
  CONST jointtarget jhome:=[[0,-90,90,0,90,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p1:=[[1900,-720,600],[0.707106781,0,0.707106781,0],[0,-2,-2,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p2:=[[1900,-720,500],[0.707106781,0,0.707106781,0],[0,-2,-2,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  PERS robtarget paux:=[[1950,-540,520],[0.707106781,0,0.707106781,0],[0,-2,-2,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p3:=[[1900,-500,520],[0.707106781,0,0.707106781,0],[0,-2,-2,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  VAR num n:=0;
  PROC main()
    ConfJ\On;
    MoveAbsJ jhome\NoEOffs,v1000,fine,tool0;
    MoveJ p1,v500,z10,thead\WObj:=wtable;
    SetDO doHead,1;   ! head on
    MoveL p2,v200,fine,thead\WObj:=wtable;
    MoveL [[1900,-600,520],[0.707106781,0,0.707106781,0],[0,-2,-2,0],[9E9,9E9,9E9,9E9,9E9,9E9]],v200,z1,thead\WObj:=wtable;
    MoveC paux,p3,v200,z1,thead\WObj:=wtable;
    WaitTime 0.5;
    FOR i FROM 1 TO 2 DO
      MoveL p3,v100,fine,thead\WObj:=wtable;
    ENDFOR
    SetDO doHead,0;
    MoveAbsJ jhome\NoEOffs,v1000,fine,tool0;
  ENDPROC
ENDMODULE
