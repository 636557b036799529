MODULE MainModule
    !***********************************************************
    !
    ! Module:  MainModule
    !
    ! Description:
    !   Pick a part on the table, find its edge, place it on the
    !   fixture, weld it (re-created for kincal)
    !
    !***********************************************************
    CONST jointtarget jHome:=[[0,-90,90,0,90,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
    CONST robtarget pSearchEnd:=[[250,300,330],[0.707106781,0,0.707106781,0],[0,-1,-1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
    VAR num nCycle:=0;

    PROC main()
        ConfJ\On;
        ConfL\On;
        MoveAbsJ jHome\NoEOffs, v1000, z50, tool0;
        Pick;
        Place;
        WeldFillet;
        MoveAbsJ jHome\NoEOffs, v1000, fine, tool0;
        nCycle := nCycle + 1;
    ENDPROC

    PROC Pick()
        MoveJ pSafe, v1000, z50, tGripper\WObj:=wobjTable;
        MoveJ pApproach, v1000, z10, tGripper\WObj:=wobjTable;
        MoveL pPick, v200, fine, tGripper\WObj:=wobjTable;
        SetDO doGripper, 1;
        WaitTime 0.3;
        GripLoad loadPart;
        SearchL \Stop, diPartEdge, pFound, pSearchEnd, v50, tGripper\WObj:=wobjTable;
        MoveL Offs(pFound,0,0,80), v200, z10, tGripper\WObj:=wobjTable;
        MoveL pApproach, v500, z10,
              tGripper\WObj:=wobjTable;
    ENDPROC

    PROC Place()
        MoveJ pSafe, v1000, z50, tGripper\WObj:=wobjFixture;
        MoveL [[150,80,200],[0.707106781,0,0.707106781,0],[0,0,-1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]],
              v500, z5, tGripper\WObj:=wobjFixture;
        MoveL pPlace, v100, fine, tGripper\TLoad:=loadPart\WObj:=wobjFixture;
        SetDO doGripper, 0;
        GripLoad load0;
        MoveL RelTool(pPlace,0,0,-100), v500, z10, tGripper\WObj:=wobjFixture;
        MoveJ pSafe, v1000, z50, tGripper\WObj:=wobjFixture;
    ENDPROC
ENDMODULE
