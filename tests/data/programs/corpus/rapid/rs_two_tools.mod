MODULE Module1
    PERS tooldata tGripper:=[TRUE,[[0.0,0.0,215.5],[1.0000000,0.0000000,0.0000000,0.0000000]],[12.5,[0,0,100],[1,0,0,0],0,0,0]];
    PERS tooldata tVacuum:=[TRUE,[[85.0,0.0,180.0],[0.9659258,0.0000000,0.2588190,0.0000000]],[4,[0,0,100],[1,0,0,0],0,0,0]];
    TASK PERS wobjdata wobjInfeed:=[FALSE,TRUE,"",[[1750.0,-600.0,450.0],[0.7071068,0.0000000,0.0000000,0.7071068]],[[0.0,0.0,0.0],[1.0000000,0.0000000,0.0000000,0.0000000]]];
    TASK PERS wobjdata wobjOutfeed:=[FALSE,TRUE,"",[[1650.0,550.0,380.0],[1.0000000,0.0000000,0.0000000,0.0000000]],[[20.0,15.0,0.0],[0.9961947,0.0000000,0.0000000,-0.0871557]]];
    CONST robtarget Target_10:=[[963.22,-200.70,595.69],[0.0043334,-0.6999326,-0.7068351,0.1022726],[-1,0,-1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
    CONST robtarget Target_20:=[[1008.67,-254.38,344.00],[0.0076339,-0.6903048,-0.7175766,0.0922220],[-1,0,-1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
    CONST robtarget Target_30:=[[1137.01,-253.58,341.14],[0.0090397,-0.6781308,-0.7258903,0.1146305],[-1,0,-1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
    CONST robtarget Target_40:=[[484.86,-870.40,671.11],[0.1305884,0.2015281,-0.9652027,-0.1035221],[0,-1,0,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
    CONST robtarget Target_50:=[[526.18,-926.97,387.76],[0.1473177,0.1652969,-0.9705359,-0.0950496],[0,-1,0,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
    CONST robtarget Target_60:=[[528.15,-1077.53,473.21],[0.1137350,0.1669239,-0.9726102,-0.1150225],[0,-1,0,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
    !***********************************************************
    !
    ! Module:  Module1
    !
    ! Description:
    !   pick from the infeed with the gripper, place with the vacuum cup
    !
    !***********************************************************
    PROC main()
        MoveAbsJ [[0,0,0,0,30,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]]\NoEOffs,v1000,z50,tool0;
        Path_10;
        Path_20;
        MoveAbsJ [[0,0,0,0,30,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]]\NoEOffs,v1000,fine,tool0;
    ENDPROC
    PROC Path_10()
        MoveJ Target_10,v1000,z100,tGripper\WObj:=wobjInfeed;
        MoveL Target_20,v200,fine,tGripper\WObj:=wobjInfeed;
        SetDO doGripper,1;
        WaitTime 0.3;
        MoveL Target_30,v500,z50,tGripper\WObj:=wobjInfeed;
    ENDPROC
    PROC Path_20()
        MoveJ Target_40,v1000,z100,tVacuum\WObj:=wobjOutfeed;
        MoveL Target_50,v200,fine,tVacuum\WObj:=wobjOutfeed;
        SetDO doGripper,0;
        MoveL Target_60,v500,z50,tVacuum\WObj:=wobjOutfeed;
    ENDPROC
ENDMODULE
