MODULE MultiMove
    !***********************************************************
    ! Coordinated pass with T_ROB2 (MultiMove, synchronized
    ! movements), re-created for kincal
    !***********************************************************
    PERS tasks taskList{2}:=[["T_ROB1"],["T_ROB2"]];
    VAR syncident sync1;
    VAR syncident sync2;
    VAR syncident sync3;
    CONST robtarget pSync10:=[[250,150,420],[0.707106781,0,0.707106781,0],[0,-1,-1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
    CONST robtarget pSync20:=[[400,150,420],[0.707106781,0,0.707106781,0],[0,-1,-1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
    CONST robtarget pSync30:=[[400,450,420],[0.707106781,0,0.707106781,0],[0,-1,-1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];

    PROC CoordinatedPass()
        MoveJ pSync10, v1000, z50, tGripper\WObj:=wobjTable;
        WaitSyncTask sync1, taskList;
        SyncMoveOn sync2, taskList;
        MoveL pSync20 \ID:=10, v200, z10, tGripper\WObj:=wobjTable;
        MoveL pSync30 \ID:=20, v200, fine, tGripper\WObj:=wobjTable;
        SyncMoveOff sync3;
    ENDPROC
ENDMODULE
