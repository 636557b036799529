MODULE MM_Rob1
  VAR syncident sync1;
  VAR syncident sync2;
  VAR syncident sync3;
  PERS tasks task_list{2}:=[["T_ROB1"],["T_ROB2"]];
  PERS tooldata tHolder:=[TRUE,[[0.0,0.0,160.0],[1.0000000,0.0000000,0.0000000,0.0000000]],[20,[0,0,100],[1,0,0,0],0,0,0]];
  TASK PERS wobjdata wobjTable:=[FALSE,TRUE,"",[[1850.0,0.0,700.0],[0.0000000,0.0000000,0.0000000,1.0000000]],[[0.0,0.0,0.0],[1.0000000,0.0000000,0.0000000,0.0000000]]];
  CONST robtarget p10:=[[-134.14,-27.77,456.57],[0.0135489,-0.9974360,-0.0032985,0.0701924],[-1,0,-1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  CONST robtarget p20:=[[-199.37,-149.14,224.22],[0.0361821,-0.9976330,-0.0126095,0.0570993],[-1,0,-1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  CONST robtarget p30:=[[-213.11,-50.33,195.88],[0.0118233,-0.9985289,-0.0015446,0.0528941],[-1,0,-1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  CONST robtarget p40:=[[-213.32,57.52,196.28],[0.0186431,0.9983450,-0.0110304,-0.0532738],[0,-1,0,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  CONST robtarget p50:=[[-199.37,149.14,224.22],[0.0361821,0.9976330,-0.0126095,-0.0570993],[0,-1,0,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  PROC main()
    MoveJ p10,v1000,z50,tHolder\WObj:=wobjTable;
    WaitSyncTask sync1,task_list;
    SyncMoveOn sync2,task_list;
    MoveL p20 \ID:=10,v200,z10,tHolder\WObj:=wobjTable;
    MoveL p30 \ID:=20,v200,fine,tHolder\WObj:=wobjTable;
    MoveC p40,p50 \ID:=30,v100,z10,tHolder\WObj:=wobjTable;
    MoveL [[-154.48,94.91,256.23],[0.0255922,0.9985697,-0.0105487,-0.0457418],[0,-1,0,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]]\ID:=40,v200,fine,tHolder\WObj:=wobjTable;
    SyncMoveOff sync3;
    MoveJ p10,v1000,fine,tHolder\WObj:=wobjTable;
  ENDPROC
ENDMODULE
